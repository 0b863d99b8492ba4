//! lumiere: a CPU Monte Carlo ray tracer.
//!
//! Data flows one way: a [`scene::Scene`] (triangles, materials, lights) and a
//! [`scene::camera::Camera`] go into a [`world::World`] (the scene plus its [`accel::Bvh4`]), which
//! [`render::render`] turns into an image through one of the [`integrators`]; [`image_io`] writes it.
//!
//! ```
//! use lumiere::integrators::Mode;
//! use lumiere::render::{RenderOptions, render};
//! use lumiere::scene::{Scene, builtin, camera::Camera};
//! use lumiere::world::World;
//!
//! let scene = Scene::builtin()?;
//! let camera = Camera::from_orbiter(&builtin::cornell_orbiter()?, 64, 48);
//! let world = World::new(scene, Default::default());
//! let options = RenderOptions::new(Mode::Shadows, 1);
//! let output = render(&world, &camera, &options, &|_| {})?;
//! assert_eq!(output.image.pixels.len(), 64 * 48);
//! assert!(output.image.pixels.iter().any(|p| p.x > 0.0), "the lit box is not black");
//! # Ok::<(), lumiere::Error>(())
//! ```

pub mod accel;
pub mod checkpoint;
pub mod error;
pub mod film;
pub mod fingerprint;
pub mod geometry;
pub mod image_io;
pub mod integrators;
pub mod lights;
pub mod math;
pub mod render;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod world;

pub use error::{Error, Result};
