//! Cameras: gKit's orbiter (reproduced matrix for matrix, so images line up with the lab's) and a
//! look-at pinhole.
//!
//! Both generate rays from continuous film coordinates `(x, y)` with `(0, 0)` the top-left corner
//! of the picture and `(w, h)` the bottom-right one; the pixel `(i, j)` is the square
//! `[i, i+1] x [j, j+1]`, its centre `(i + 0.5, j + 0.5)`.

use std::path::Path;

use glam::{DMat4, DVec2, DVec3, DVec4, Vec3};

use crate::error::{Error, Result, quote};
use crate::math::{Aabb, Ray};

/// gKit's `Orbiter` state as stored in its text files (`c`, `p`, `r`, `s`, optional `f` lines).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbiter {
    pub center: DVec3,
    pub pan: DVec2,
    /// Rotations about x then y, degrees.
    pub rotation: DVec2,
    pub size: f64,
    pub radius: f64,
    /// `f fov width height`, informative only: the lab overrides it with `projection(w, h, 45)`.
    pub frame: Option<(f64, f64, f64)>,
}

impl Orbiter {
    pub fn load(path: &Path) -> Result<Orbiter> {
        let text = crate::util::read::read_regular_file(path).map_err(|e| Error::io(path, e))?;
        Orbiter::parse(&text, path)
    }

    /// Parses orbiter text; `path` names the file in errors.
    pub fn parse(bytes: &[u8], path: &Path) -> Result<Orbiter> {
        let mut fields: [Option<Vec<f64>>; 5] = Default::default();
        let mut size_line = 0;
        for (index, raw) in bytes.split(|&b| b == b'\n').enumerate() {
            let line = index + 1;
            let text = std::str::from_utf8(raw).map_err(|_| Error::parse(path, line, "not UTF-8 text"))?;
            let mut tokens = text.split_whitespace();
            let Some(key) = tokens.next() else { continue };
            let (slot, arity) = match key {
                "c" => (0, 3),
                "p" => (1, 2),
                "r" => (2, 2),
                "s" => (3, 2),
                "f" => (4, 3),
                _ if key.starts_with('#') => continue,
                _ => {
                    return Err(Error::parse(
                        path,
                        line,
                        format!("unknown orbiter field {} (expected c, p, r, s or f)", quote(key)),
                    ));
                }
            };
            let values = tokens
                .map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or(t))
                .collect::<std::result::Result<Vec<f64>, &str>>()
                .map_err(|t| Error::parse(path, line, format!("'{key}' expects finite numbers, found {}", quote(t))))?;
            if values.len() != arity {
                return Err(Error::parse(
                    path,
                    line,
                    format!("'{key}' expects {arity} numbers, found {}", values.len()),
                ));
            }
            fields[slot] = Some(values);
            if key == "s" {
                size_line = line;
            }
        }
        // A missing line is reported at the end of the file: its last line, as an editor counts
        // them (a final newline does not start another), or line 1 of an empty file.
        let last_line = bytes.strip_suffix(b"\n").unwrap_or(bytes).split(|&b| b == b'\n').count();
        let mut take = |slot: usize, key: &str| {
            fields[slot].take().ok_or_else(|| Error::parse(path, last_line, format!("missing '{key}' line")))
        };
        let (c, p, r, s) = (take(0, "c")?, take(1, "p")?, take(2, "r")?, take(3, "s")?);
        let frame = fields[4].take().map(|f| (f[0], f[1], f[2]));
        let orbiter = Orbiter {
            center: DVec3::new(c[0], c[1], c[2]),
            pan: DVec2::new(p[0], p[1]),
            rotation: DVec2::new(r[0], r[1]),
            size: s[0],
            radius: s[1],
            frame,
        };
        // Finite numbers can still make a camera without rays: gKit's near and far planes meet
        // where the radius is nothing beside the distance to the centre (its projection divides by
        // their difference), planes too far apart or huge numbers overflow the matrices. Every
        // pixel's ray would be NaN, the image black.
        let (near, far) = orbiter.clip_planes();
        if near.is_finite() && far <= near {
            let message = format!(
                "'s' gives a radius of {:?} at a distance of {near:?} from the centre: the near and far planes \
                 meet, so the camera has no depth to cast rays through (gKit's orbiters keep the scene's radius there)",
                orbiter.radius
            );
            return Err(Error::parse(path, size_line, message));
        }
        if !orbiter.casts_finite_rays() {
            let message = format!(
                "the camera's rays are not finite: its numbers overflow, or its near and far planes ({near:?} and \
                 {far:?}, from the radius and the distance to the centre) are too far apart for its matrices"
            );
            return Err(Error::parse(path, size_line, message));
        }
        Ok(orbiter)
    }

    /// gKit's `Orbiter::view()`.
    pub fn view(&self) -> DMat4 {
        DMat4::from_translation(DVec3::new(-self.pan.x, -self.pan.y, -self.size))
            * DMat4::from_rotation_x(self.rotation.x.to_radians())
            * DMat4::from_rotation_y(self.rotation.y.to_radians())
            * DMat4::from_translation(-self.center)
    }

    /// gKit's `Orbiter::projection(width, height, fov)`, near/far planes computed as gKit does.
    pub fn projection(&self, width: f64, height: f64, fov_degrees: f64) -> DMat4 {
        let (znear, zfar) = self.clip_planes();
        gl_perspective(fov_degrees, width / height, znear, zfar)
    }

    /// Whether the camera of this orbiter casts finite rays through the corners and the centre of
    /// the picture (the aspect ratio scales them in x only).
    fn casts_finite_rays(&self) -> bool {
        let camera = Camera::from_orbiter(self, 4, 3);
        [(0.0, 0.0), (4.0, 0.0), (0.0, 3.0), (4.0, 3.0), (2.0, 1.5)].iter().all(|&(x, y)| {
            let ray = camera.ray(x, y);
            ray.origin.is_finite() && ray.dir.is_finite() && ray.dir != Vec3::ZERO
        })
    }

    /// The distances of the near and far planes, computed as gKit does.
    fn clip_planes(&self) -> (f64, f64) {
        let d = self.center.distance(DVec3::new(self.pan.x, self.pan.y, self.size));
        ((d - self.radius).max(0.1), (d + self.radius).max(1.0))
    }
}

/// OpenGL's perspective matrix, as gKit's `Perspective()` builds it.
fn gl_perspective(fov_degrees: f64, aspect: f64, znear: f64, zfar: f64) -> DMat4 {
    let itan = 1.0 / (fov_degrees.to_radians() / 2.0).tan();
    let id = 1.0 / (znear - zfar);
    DMat4::from_cols(
        DVec4::new(itan / aspect, 0.0, 0.0, 0.0),
        DVec4::new(0.0, itan, 0.0, 0.0),
        DVec4::new(0.0, 0.0, (zfar + znear) * id, -1.0),
        DVec4::new(0.0, 0.0, 2.0 * zfar * znear * id, 0.0),
    )
}

/// gKit's `Viewport(width, height)`: NDC to pixel coordinates, depth to [0, 1].
fn gl_viewport(width: f64, height: f64) -> DMat4 {
    DMat4::from_cols(
        DVec4::new(width / 2.0, 0.0, 0.0, 0.0),
        DVec4::new(0.0, height / 2.0, 0.0, 0.0),
        DVec4::new(0.0, 0.0, 0.5, 0.0),
        DVec4::new(width / 2.0, height / 2.0, 0.5, 1.0),
    )
}

#[derive(Clone, Debug, PartialEq)]
enum Projection {
    /// Image space to world: `inverse(viewport * projection * view)`, gKit's `y = 0` at the bottom.
    ImageToWorld(DMat4),
    /// Pinhole at `eye`; `right`/`up` are scaled so that film corners map to `forward ± right ± up`.
    Pinhole { eye: Vec3, forward: Vec3, right: Vec3, up: Vec3 },
}

/// A camera producing one ray per film position.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub width: u32,
    pub height: u32,
    projection: Projection,
}

impl Camera {
    /// gKit's camera for the lab: `orbiter.projection(width, height, 45)`.
    pub fn from_orbiter(orbiter: &Orbiter, width: u32, height: u32) -> Camera {
        let (w, h) = (width as f64, height as f64);
        let m = gl_viewport(w, h) * orbiter.projection(w, h, 45.0) * orbiter.view();
        Camera { width, height, projection: Projection::ImageToWorld(m.inverse()) }
    }

    /// A pinhole at `eye` looking at `target`, with vertical field of view `fov_degrees`.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, fov_degrees: f32, width: u32, height: u32) -> Result<Camera> {
        if !(eye.is_finite() && target.is_finite()) {
            return Err(Error::invalid(format!("camera: the eye {eye} and the target {target} must be finite")));
        }
        let view = target - eye;
        if !view.is_finite() {
            return Err(Error::invalid(
                "camera: the eye and the target are too far apart (their difference overflows)",
            ));
        }
        // Scaled by its largest component first, so that a long but finite view does not overflow
        // its squared length.
        let forward = (view / view.abs().max_element())
            .try_normalize()
            .ok_or_else(|| Error::invalid("camera: the eye and the target are the same point"))?;
        if !up.is_finite() {
            return Err(Error::invalid(format!("camera: the up vector {up} must be finite")));
        }
        // A long but finite up vector overflows the cross product or its length: scaled then (only
        // then, so that every other camera keeps its bits), as the view is.
        let side = forward.cross(up);
        let side = if side.length_squared().is_finite() { side } else { forward.cross(up / up.abs().max_element()) };
        let right = side
            .try_normalize()
            .ok_or_else(|| Error::invalid("camera: the up vector is zero or parallel to the viewing direction"))?;
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(Error::invalid(format!(
                "camera: the field of view must be in (0, 180) degrees, got {fov_degrees}"
            )));
        }
        let half_height = (fov_degrees.to_radians() / 2.0).tan();
        let half_width = half_height * width as f32 / height as f32;
        let true_up = right.cross(forward);
        Ok(Camera {
            width,
            height,
            projection: Projection::Pinhole { eye, forward, right: right * half_width, up: true_up * half_height },
        })
    }

    /// The ray through film position `(x, y)` (top-left origin), with a unit direction.
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        match &self.projection {
            Projection::ImageToWorld(inv) => {
                let (origin, extremity) = image_to_world(inv, x as f64, self.height as f64 - y as f64);
                Ray::new(origin.as_vec3(), (extremity - origin).normalize().as_vec3())
            }
            Projection::Pinhole { eye, forward, right, up } => {
                let sx = 2.0 * x / self.width as f32 - 1.0;
                let sy = 1.0 - 2.0 * y / self.height as f32;
                Ray::new(*eye, (*forward + sx * *right + sy * *up).normalize())
            }
        }
    }

    /// [`Camera::ray`] for `N` film positions at once, the same rays bit for bit: each lane does
    /// `ray`'s operations in their order (glam's `project_point3`, `normalize` and `dot`), in loops
    /// over the lanes that the caller's ISA vectorises (run it inside `World::simd`). A gKit
    /// camera's ray costs two projections, six divisions and a square root in f64: an eighth of a
    /// hard-shadow render, one ray at a time.
    #[inline(always)]
    pub fn rays<const N: usize>(&self, xs: &[f32; N], ys: &[f32; N]) -> [Ray; N] {
        match &self.projection {
            Projection::ImageToWorld(inv) => {
                let (columns, height) = (inv.to_cols_array_2d(), self.height as f64);
                let mut origin = [[0.0f64; N]; 3];
                let mut dir = [[0.0f64; N]; 3];
                for lane in 0..N {
                    let (x, y) = (xs[lane] as f64, height - ys[lane] as f64);
                    // `project_point3` of (x, y, 0) and (x, y, 1): x and y columns first, then z, then w.
                    let xy: [f64; 4] = std::array::from_fn(|c| columns[1][c] * y + columns[0][c] * x);
                    let near: [f64; 4] = std::array::from_fn(|c| columns[3][c] + (columns[2][c] * 0.0 + xy[c]));
                    let far: [f64; 4] = std::array::from_fn(|c| columns[3][c] + (columns[2][c] * 1.0 + xy[c]));
                    let o: [f64; 3] = std::array::from_fn(|c| near[c] / near[3]);
                    let e: [f64; 3] = std::array::from_fn(|c| far[c] / far[3]);
                    let d: [f64; 3] = std::array::from_fn(|c| e[c] - o[c]);
                    let recip = 1.0 / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    for c in 0..3 {
                        origin[c][lane] = o[c];
                        dir[c][lane] = d[c] * recip;
                    }
                }
                std::array::from_fn(|lane| {
                    let vector = |v: &[[f64; N]; 3]| DVec3::new(v[0][lane], v[1][lane], v[2][lane]).as_vec3();
                    Ray::new(vector(&origin), vector(&dir))
                })
            }
            Projection::Pinhole { eye, forward, right, up } => {
                let (width, height) = (self.width as f32, self.height as f32);
                let mut dir = [[0.0f32; N]; 3];
                for lane in 0..N {
                    let sx = 2.0 * xs[lane] / width - 1.0;
                    let sy = 1.0 - 2.0 * ys[lane] / height;
                    let d: [f32; 3] = std::array::from_fn(|c| forward[c] + sx * right[c] + sy * up[c]);
                    let recip = 1.0 / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    for c in 0..3 {
                        dir[c][lane] = d[c] * recip;
                    }
                }
                std::array::from_fn(|lane| Ray::new(*eye, Vec3::new(dir[0][lane], dir[1][lane], dir[2][lane])))
            }
        }
    }

    /// For gKit cameras, the lab's ray endpoints for image position `(x, y)` with `y = 0` at the
    /// bottom: `inv(x, y, 0)` on the near plane and `inv(x, y, 1)` on the far plane. `None` for pinholes.
    pub fn gkit_ray_endpoints(&self, x: f64, y: f64) -> Option<(DVec3, DVec3)> {
        match &self.projection {
            Projection::ImageToWorld(inv) => Some(image_to_world(inv, x, y)),
            Projection::Pinhole { .. } => None,
        }
    }
}

/// The view a scene file gives itself (a glTF camera): a look-at camera less its image size. The
/// size decides the horizontal field of view, as for every look-at camera (a glTF camera's
/// `aspectRatio` is not read).
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    pub eye: Vec3,
    /// A point on the view's axis (where the target lies along it does not change the view).
    pub target: Vec3,
    /// Unit, though not always square to the axis: [`Camera::look_at`] squares it.
    pub up: Vec3,
    /// The vertical field of view, in degrees.
    pub fov_degrees: f32,
    /// The name the file gives the camera (else its node), for the user to recognise it.
    pub name: Option<String>,
}

/// The eye and target of a view from +z that frames all of `bounds` (its bounding sphere fills the
/// vertical field of view `fov_degrees`): the camera front ends use when none is given. Refused,
/// with the reason, for empty bounds, a field of view out of range or too narrow to frame them
/// from a finite distance, or bounds too large to frame in `f32`.
pub fn framing(bounds: &Aabb, fov_degrees: f32) -> std::result::Result<(Vec3, Vec3), String> {
    if bounds.is_empty() {
        return Err("no vertices to frame".into());
    }
    if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
        return Err(format!("the field of view must be in (0, 180) degrees, got {fov_degrees:?}"));
    }
    let radius = 0.5 * bounds.extent().length();
    let distance = radius / (0.5 * fov_degrees.to_radians()).sin();
    let target = bounds.center();
    // Beyond this many radii away, single precision places the rays within more than 1/2^7 of the
    // radius: a field of view under about 0.002 degrees, whose view is black or noise.
    const MAX_DISTANCE_IN_RADII: f32 = 65536.0;
    if radius.is_finite() && target.is_finite() && (distance.is_nan() || distance > MAX_DISTANCE_IN_RADII * radius) {
        return Err(format!("a field of view of {fov_degrees:?} degrees is too narrow to frame it"));
    }
    let eye = target + Vec3::Z * distance.max(1e-6);
    if !(eye.is_finite() && target.is_finite()) || eye == target {
        return Err("its bounds are too large (or too far from the origin) to frame automatically".into());
    }
    Ok((eye, target))
}

/// Maps image position `(x, y)` at depths 0 and 1 back to world space (with the divide by w).
fn image_to_world(inv: &DMat4, x: f64, y: f64) -> (DVec3, DVec3) {
    (inv.project_point3(DVec3::new(x, y, 0.0)), inv.project_point3(DVec3::new(x, y, 1.0)))
}
