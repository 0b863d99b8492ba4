//! The benchmark scenes of `../shared/scenes` with the cameras their README recommends.

use std::path::Path;

use glam::Vec3;

use lumiere::error::Result;
use lumiere::scene::camera::Camera;
use lumiere::scene::{Scene, builtin};

/// A benchmark scene: where it comes from and how to look at it.
#[derive(Clone, Copy, Debug)]
pub struct BenchScene {
    pub name: &'static str,
    /// Path relative to the scenes folder; `None` for the built-in Cornell box.
    pub file: Option<&'static str>,
    pub width: u32,
    pub height: u32,
    camera: CameraSpec,
}

#[derive(Clone, Copy, Debug)]
enum CameraSpec {
    BuiltinOrbiter,
    LookAt { eye: [f32; 3], target: [f32; 3], up: [f32; 3], fov: f32 },
}

const BUNNY_CAMERA: CameraSpec = CameraSpec::LookAt {
    eye: [-0.016841, 0.110154, 0.338463],
    target: [-0.016841, 0.110154, -0.001537],
    up: [0.0, 1.0, 0.0],
    fov: 30.0,
};

pub const SCENES: [BenchScene; 4] = [
    BenchScene { name: "cornell", file: None, width: 1024, height: 768, camera: CameraSpec::BuiltinOrbiter },
    BenchScene {
        name: "bunny",
        file: Some("bunny/stanford-bunny.obj"),
        width: 1024,
        height: 768,
        camera: BUNNY_CAMERA,
    },
    BenchScene {
        name: "bunny-1m",
        file: Some("bunny-1m/stanford-bunny-1m.obj.gz"),
        width: 1024,
        height: 768,
        camera: BUNNY_CAMERA,
    },
    BenchScene {
        name: "staircase",
        file: Some("staircase/staircase.obj.gz"),
        width: 720,
        height: 1280,
        camera: CameraSpec::LookAt {
            eye: [0.0324209, 1.52673, 4.88197],
            target: [0.0247749, 1.571785, 3.883015],
            up: [0.000344842, 0.998984, 0.0450537],
            fov: 58.54,
        },
    },
];

impl BenchScene {
    pub fn by_name(name: &str) -> Option<BenchScene> {
        SCENES.iter().copied().find(|s| s.name == name)
    }

    pub fn load(&self, scenes_dir: &Path) -> Result<Scene> {
        match self.file {
            None => Scene::builtin(),
            Some(file) => Scene::load(&scenes_dir.join(file)),
        }
    }

    pub fn camera(&self) -> Result<Camera> {
        match self.camera {
            CameraSpec::BuiltinOrbiter => {
                Ok(Camera::from_orbiter(&builtin::cornell_orbiter()?, self.width, self.height))
            }
            CameraSpec::LookAt { eye, target, up, fov } => Camera::look_at(
                Vec3::from_array(eye),
                Vec3::from_array(target),
                Vec3::from_array(up),
                fov,
                self.width,
                self.height,
            ),
        }
    }
}
