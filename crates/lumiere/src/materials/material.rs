//! The format-neutral description of a surface, as scene loaders fill it (from MTL statements
//! today). Integrators never read it directly: they ask it for its [`Bsdf`](super::Bsdf).

use glam::Vec3;

use super::Lambert;
use std::path::PathBuf;

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Diffuse reflectance.
    pub kd: Vec3,
    /// Specular reflectance.
    pub ks: Vec3,
    /// Phong exponent.
    pub ns: f32,
    /// Emitted radiance; a non-zero value makes every triangle with this material a light.
    pub ke: Vec3,
    /// Diffuse texture, resolved relative to the MTL file.
    pub map_kd: Option<PathBuf>,
    /// Index of refraction.
    pub ni: f32,
    /// Opacity (`d`), 1 = opaque.
    pub dissolve: f32,
    pub illum: u32,
}

impl Material {
    /// The grey diffuse material used when a file names no material or its MTL cannot be read.
    pub fn default_grey(name: &str) -> Self {
        Material {
            name: name.to_string(),
            kd: Vec3::splat(0.8),
            ks: Vec3::ZERO,
            ns: 0.0,
            ke: Vec3::ZERO,
            map_kd: None,
            ni: 1.0,
            dissolve: 1.0,
            illum: 1,
        }
    }

    pub fn is_emissive(&self) -> bool {
        self.ke.max_element() > 0.0
    }
}

impl Material {
    /// The scattering function of this material: Lambertian reflection of `kd` (the only lobe so far).
    #[inline]
    pub fn bsdf(&self) -> Lambert {
        Lambert { reflectance: self.kd }
    }
}
