//! The diffuse vertices of a bounce, scattered together: `Path::scatter` for a Lambertian surface,
//! for every lane of the lockstep paths at once, SoA, in one loop that the ISA vectorises whole.
//! Each lane performs the scalar vertex's operations in their order: the same functions where
//! they are pure (the frame, the triangle warp, the BSDF's `eval`, `pdf` and `sample`, the MIS
//! weight, the offset origins of the rays it spawns) and `LightSet::sample_li_on`'s arithmetic written out, with every branch turned into a
//! select, so that it gets the bits `Path::scatter` gives it (`packets.rs` and the golden images
//! compare them on every ISA).
//!
//! Scattered one lane at a time, the vertices of the path-traced Cornell box took a quarter of its
//! time, in chains of dependent square roots and divisions that one lane cannot overlap.

use glam::{Vec2, Vec3};

use crate::geometry::surface::SurfacePoint;
use crate::lights::AreaLight;
use crate::materials::{Bsdf, Lambert};
use crate::math::rows::{Rows, row, set_row};
use crate::math::{Frame, Ray};
use crate::sampling::warp::sample_uniform_triangle;

/// What the lanes' vertices know before scattering, SoA: the surface, the arriving path, the
/// light chosen for next-event estimation and the vertex's numbers.
pub(super) struct DiffuseVertices<const N: usize> {
    pub p: Rows<N>,
    pub ng: Rows<N>,
    pub ns: Rows<N>,
    /// The arriving ray's (unit) direction.
    pub dir: Rows<N>,
    pub throughput: Rows<N>,
    pub reflectance: Rows<N>,
    /// The light chosen for each lane.
    pub light: LightRows<N>,
    /// The point on the light: the part of the light number the choice left, then its `y`.
    pub light_point: [Vec2; N],
    pub scatter_point: [Vec2; N],
    pub survival: [f32; N],
    /// Lanes that play Russian roulette at this vertex.
    pub roulette: u32,
}

/// The chosen lights' records, SoA.
pub(super) struct LightRows<const N: usize> {
    pub targets: [Rows<N>; 3],
    pub normal: Rows<N>,
    pub area: [f32; N],
    pub emission: Rows<N>,
    /// The probability of the choice.
    pub pmf: [f32; N],
    /// Lanes with a light chosen (none in a scene without lights): the others draw no light sample.
    pub chosen: u32,
}

impl<const N: usize> LightRows<N> {
    /// Records lane `lane`'s choice of `light`, with probability `pmf`.
    #[inline(always)]
    pub fn choose(&mut self, lane: usize, light: &AreaLight, pmf: f32) {
        for (rows, &target) in self.targets.iter_mut().zip(&light.shadow_targets) {
            set_row(rows, lane, target);
        }
        set_row(&mut self.normal, lane, light.normal);
        set_row(&mut self.emission, lane, light.emission);
        self.area[lane] = light.area;
        self.pmf[lane] = pmf;
        self.chosen |= 1 << lane;
    }
}

impl<const N: usize> Default for DiffuseVertices<N> {
    fn default() -> Self {
        let rows = [[0.0; N]; 3];
        DiffuseVertices {
            p: rows,
            ng: rows,
            ns: rows,
            dir: rows,
            throughput: rows,
            reflectance: rows,
            light: LightRows {
                targets: [rows; 3],
                normal: rows,
                area: [0.0; N],
                emission: rows,
                pmf: [0.0; N],
                chosen: 0,
            },
            light_point: [Vec2::ZERO; N],
            scatter_point: [Vec2::ZERO; N],
            survival: [0.0; N],
            roulette: 0,
        }
    }
}

/// What the vertices' scattering gives, SoA: the light samples to test (their shadow segments,
/// which end at `t = 1`, and contributions if unblocked) and the paths' next rays, throughputs and
/// densities.
pub(super) struct DiffuseScattering<const N: usize> {
    /// Lanes with a light sample to test.
    pub shadowed: u32,
    pub segment_origin: Rows<N>,
    pub segment_dir: Rows<N>,
    pub contribution: Rows<N>,
    /// Lanes whose path goes on.
    pub continues: u32,
    pub origin: Rows<N>,
    pub wi: Rows<N>,
    pub throughput: Rows<N>,
    pub pdf: [f32; N],
}

impl<const N: usize> DiffuseScattering<N> {
    /// Lane `lane`'s shadow segment.
    #[inline(always)]
    pub fn segment(&self, lane: usize) -> Ray {
        Ray { origin: row(&self.segment_origin, lane), dir: row(&self.segment_dir, lane), tmax: 1.0 }
    }

    /// Lane `lane`'s next ray.
    #[inline(always)]
    pub fn ray(&self, lane: usize) -> Ray {
        Ray::new(row(&self.origin, lane), row(&self.wi, lane))
    }
}

impl<const N: usize> DiffuseVertices<N> {
    /// Scatters every lane (run it in `World::simd_256`): lanes not filled in compute numbers nobody
    /// reads. `light_weight_over_pdf` is the path tracer's MIS weight of a light sample over its
    /// density (a function without branches on anything but its arguments, or the loop stays
    /// scalar).
    #[inline(always)]
    #[expect(clippy::needless_range_loop, reason = "a lane indexes a dozen SoA rows")]
    pub fn scatter(&self, light_weight_over_pdf: impl Fn(f32, f32) -> f32) -> DiffuseScattering<N> {
        // Locals, not the fields of the result: the compiler does not vectorise the loop when its
        // masks share memory with its rows.
        let (mut shadowed, mut continues) = (0u32, 0u32);
        let rows = [[0.0; N]; 3];
        let (mut segment_origins, mut segment_dirs, mut contributions) = (rows, rows, rows);
        let (mut origins, mut wis, mut throughputs, mut pdfs) = (rows, rows, rows, [0.0; N]);
        let light = &self.light;
        for lane in 0..N {
            let (ng, throughput) = (row(&self.ng, lane), row(&self.throughput, lane));
            // The surface point as far as spawning rays from it goes.
            let surface = SurfacePoint { p: row(&self.p, lane), ng, ..Default::default() };
            let bsdf = Lambert { reflectance: row(&self.reflectance, lane) };
            // A Lambertian surface does not transmit: its frame is the shading normal's.
            let frame = Frame::from_normal(row(&self.ns, lane));
            let wo = frame.to_local(-row(&self.dir, lane));
            // `f_cos`'s test: `wi` is a reflection in the geometry exactly when it is one in the frame.
            let sides_agree = |wi: Vec3, local: Vec3| (ng.dot(wi) > 0.0) == (local.z * wo.z > 0.0);

            // Next-event estimation: `LightSet::sample_li_on`, its pdf times the choice's.
            let b = sample_uniform_triangle(self.light_point[lane]);
            // Written out, not `.map(..)`, whose call is not always inlined (see `direct.rs`).
            let [t0, t1, t2] =
                [row(&light.targets[0], lane), row(&light.targets[1], lane), row(&light.targets[2], lane)];
            let target = b.x * t0 + b.y * t1 + b.z * t2;
            let v = target - surface.p;
            let dist2 = v.length_squared();
            let dist = dist2.sqrt();
            let inv_dist = 1.0 / dist;
            let wi = v * inv_dist;
            let cos_light_dist = -row(&light.normal, lane).dot(v);
            let sampled = light.chosen >> lane & 1 != 0 && !(cos_light_dist <= 0.0 || dist2 <= 0.0);
            let light_pdf = dist2 * dist / (cos_light_dist * light.area[lane]) * light.pmf[lane];
            let local = frame.to_local(wi);
            let f_cos = if sides_agree(wi, local) { bsdf.eval(wo, local) * local.z.abs() } else { Vec3::ZERO };
            let weight = light_weight_over_pdf(light_pdf, bsdf.pdf(wo, local));
            let contribution = throughput * f_cos * row(&light.emission, lane) * weight;
            shadowed |= u32::from(sampled && f_cos != Vec3::ZERO) << lane;
            let segment = surface.spawn_segment(target);
            set_row(&mut segment_origins, lane, segment.origin);
            set_row(&mut segment_dirs, lane, segment.dir);
            set_row(&mut contributions, lane, contribution);

            // BSDF sampling, then Russian roulette: survive with probability q, weigh by 1/q.
            let (scattered, f, local, pdf) = match bsdf.sample(wo, self.scatter_point[lane]) {
                Some(s) => (true, s.f, s.wi, s.pdf),
                None => (false, Vec3::ZERO, Vec3::Z, 1.0),
            };
            let wi = frame.to_world(local);
            let mut throughput = throughput * (f * (local.z.abs() / pdf));
            let q = throughput.max_element().min(0.95);
            let roulette = self.roulette >> lane & 1 != 0;
            let finite = throughput.is_finite();
            let survives = !roulette || self.survival[lane] < q;
            if roulette {
                throughput /= q;
            }
            continues |= u32::from(scattered && sides_agree(wi, local) && finite && survives) << lane;
            set_row(&mut origins, lane, surface.spawn_ray(wi).origin);
            set_row(&mut wis, lane, wi);
            set_row(&mut throughputs, lane, throughput);
            pdfs[lane] = pdf;
        }
        DiffuseScattering {
            shadowed,
            segment_origin: segment_origins,
            segment_dir: segment_dirs,
            contribution: contributions,
            continues,
            origin: origins,
            wi: wis,
            throughput: throughputs,
            pdf: pdfs,
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::DiffuseVertices;
    use crate::math::rows::set_row;

    /// Russian roulette survives with probability `q` for survival numbers uniform on `[0, 1)`:
    /// the numbers below `q` survive, `q` itself does not (`Path::scatter` ends the path for
    /// `survival >= q`). Two lanes of a white Lambertian vertex seen head-on keep their throughput
    /// at 1, so `q` is its cap, 0.95, exactly: one draws `q`, the other the number just below it.
    #[test]
    fn diffuse_roulette_ends_the_path_whose_number_equals_the_survival_probability() {
        let q = 0.95f32;
        let mut v = DiffuseVertices::<2>::default();
        for (lane, survival) in [q, q.next_down()].into_iter().enumerate() {
            set_row(&mut v.ng, lane, Vec3::Z);
            set_row(&mut v.ns, lane, Vec3::Z);
            set_row(&mut v.dir, lane, -Vec3::Z);
            set_row(&mut v.throughput, lane, Vec3::ONE);
            set_row(&mut v.reflectance, lane, Vec3::ONE);
            v.scatter_point[lane] = Vec2::splat(0.5);
            v.survival[lane] = survival;
            v.roulette |= 1 << lane;
        }
        let out = v.scatter(|_, _| 0.0);
        assert_eq!(out.continues, 0b10, "the number q ends the path, the one below it survives");
    }
}
