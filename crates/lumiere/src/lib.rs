//! lumiere: a CPU Monte Carlo ray tracer.
//!
//! Data flows one way (docs/ARCHITECTURE.md): a [`scene::Scene`] (loaded from a file, embedded, or
//! built from parts) becomes a [`world::World`] (the scene with its BVH and lights, derived once);
//! [`render::render`] turns the world and a [`scene::camera::Camera`] into a
//! [`render::film::Image`] through the [`integrators`] named by a [`integrators::Technique`];
//! [`image_io`] writes it.
//!
//! ```
//! use lumiere::integrators::{Shadows, Technique};
//! use lumiere::render::{RenderOptions, render};
//! use lumiere::scene::{Scene, builtin, camera::Camera};
//! use lumiere::world::World;
//!
//! let scene = Scene::builtin()?;
//! let camera = Camera::from_orbiter(&builtin::cornell_orbiter()?, 64, 48);
//! let world = World::new(scene, Default::default());
//! let options = RenderOptions::new(Technique::Shadows(Shadows));
//! let output = render(&world, &camera, &options, &|_| {})?;
//! assert_eq!(output.image.pixels.len(), 64 * 48);
//! assert!(output.image.pixels.iter().any(|p| p.x > 0.0), "the lit box is not black");
//! # Ok::<(), lumiere::Error>(())
//! ```

pub mod accel;
pub mod error;
pub mod geometry;
pub mod image_io;
pub mod integrators;
pub mod lights;
pub mod materials;
pub mod math;
pub mod render;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod textures;
pub mod util;
pub mod world;

pub use error::{Error, Result};
