//! The default scene, embedded in the binary: gKit's Cornell box and its 2022 orbiter camera.

use std::path::{Path, PathBuf};

use super::camera::Orbiter;
use super::load::obj::{ObjScene, parse_obj};
use crate::error::Result;

const OBJ: &[u8] = include_bytes!("../../assets/cornell/cornell.obj");
const MTL: &[u8] = include_bytes!("../../assets/cornell/cornell.mtl");
const ORBITER: &[u8] = include_bytes!("../../assets/cornell/cornell_orbiter.txt");

/// The name the built-in scene goes by in messages and statistics.
pub const NAME: &str = "builtin:cornell";

/// The lab's image size.
pub const WIDTH: u32 = 1024;
pub const HEIGHT: u32 = 768;

pub fn cornell_box() -> Result<ObjScene> {
    let read_mtl = |name: &str| {
        if name == "cornell.mtl" {
            Ok((MTL.to_vec(), PathBuf::from("builtin:cornell.mtl")))
        } else {
            Err(std::io::Error::new(std::io::ErrorKind::NotFound, format!("{name} is not embedded")))
        }
    };
    parse_obj(OBJ, Path::new("builtin:cornell.obj"), &read_mtl)
}

pub fn cornell_orbiter() -> Result<Orbiter> {
    Orbiter::parse(ORBITER, Path::new("builtin:cornell_orbiter.txt"))
}
