//! The accel a render uses: the wide BVH of one [`Isa`], chosen once, with one entry point per
//! query that forwards to that BVH's monomorphised traversal.
//!
//! Every ISA returns the same hits bit for bit (the kernels perform the scalar test's operations in
//! the same order, and ties go to the lower triangle id whatever the tree), so the choice changes
//! speed and never an image.

use glam::Vec3;

use super::bvh2::{BuildPreset, Bvh};
use super::simd::lanes_of;
use super::simd::portable::F32xN;
use super::wide::{PacketKey, RayPacket, WideBvh};
use super::{Bvh4, Hit, Isa, OriginBatch, Region, TraversalStats, VisitOrder, visit_order};
use crate::math::Ray;

/// Fewer rays than this sharing a [`PacketKey`] are traced one by one: a packet's walk costs about
/// what the walk of the union of its rays' paths does, which a handful of rays do not amortise.
/// A choice, not tuned.
const MIN_PACKET_RAYS: u32 = 4;

/// A BVH built for one instruction set.
#[derive(Clone, Debug)]
pub struct Accel {
    bvh: IsaBvh,
    isa: Isa,
}

/// The layout and kernel of each ISA. The AVX kernels' types are private to `accel`, which keeps
/// them out of reach of code that has not checked [`Isa::is_supported`]. Both AVX ISAs walk the
/// tree with the AVX2 kernel; they differ in what [`Accel::simd`] compiles for.
#[derive(Clone, Debug)]
enum IsaBvh {
    Portable(WideBvh<4, F32xN<4>>),
    Sse2(Bvh4),
    #[cfg(target_arch = "x86_64")]
    Avx2(WideBvh<8, super::simd::avx::F32x8<super::simd::avx::Avx2>>),
    /// The AVX2 traversal: compiled for AVX-512 it measured 4-8% slower on this project's Xeon
    /// (hard shadows, path tracing; the same speed on the bunny), while the lane loops of
    /// [`Accel::simd`] gain from AVX-512's 16 lanes (ambient occlusion N=256: 1.24x), so this ISA
    /// uses each where it measured faster.
    #[cfg(target_arch = "x86_64")]
    Avx512(WideBvh<8, super::simd::avx::F32x8<super::simd::avx::Avx2>>),
}

/// Evaluates `$body` with `$bvh` bound to the accel's BVH, whatever its type.
macro_rules! with_bvh {
    ($accel:expr, $bvh:ident => $body:expr) => {
        match &$accel.bvh {
            IsaBvh::Portable($bvh) => $body,
            IsaBvh::Sse2($bvh) => $body,
            #[cfg(target_arch = "x86_64")]
            IsaBvh::Avx2($bvh) => $body,
            #[cfg(target_arch = "x86_64")]
            IsaBvh::Avx512($bvh) => $body,
        }
    };
}

impl Accel {
    /// Builds the binary SAH tree for `isa`'s leaf width and collapses it to `isa`'s layout.
    ///
    /// # Panics
    /// If this CPU cannot run `isa` ([`Isa::is_supported`]): callers check user input first.
    pub fn build(positions: &[Vec3], indices: &[[u32; 3]], preset: BuildPreset, isa: Isa) -> Accel {
        let binary = match isa.width() {
            4 => Bvh::build_tree_for_width::<4>(positions, indices, preset),
            _ => Bvh::build_tree_for_width::<8>(positions, indices, preset),
        };
        let corners = |slot: usize| indices[binary.triangle_id(slot) as usize].map(|i| positions[i as usize]);
        Accel::collapse(&binary, isa, corners)
    }

    /// Collapses the tree of `binary`, with the corners of leaf-order slot `i` at `corners(i)`.
    fn collapse(binary: &Bvh, isa: Isa, corners: impl Fn(usize) -> [Vec3; 3] + Sync) -> Accel {
        assert!(isa.is_supported(), "this CPU cannot run the {isa} kernels");
        let bvh = match isa {
            Isa::Portable => IsaBvh::Portable(WideBvh::from_tree(binary, corners)),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => IsaBvh::Avx2(WideBvh::from_tree(binary, corners)),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => IsaBvh::Avx512(WideBvh::from_tree(binary, corners)),
            _ => IsaBvh::Sse2(WideBvh::from_tree(binary, corners)),
        };
        Accel { bvh, isa }
    }

    pub fn isa(&self) -> Isa {
        self.isa
    }

    pub fn node_count(&self) -> usize {
        with_bvh!(self, bvh => bvh.nodes().len())
    }

    /// Bytes held by the nodes and the triangle blocks.
    pub fn memory_bytes(&self) -> usize {
        with_bvh!(self, bvh => bvh.memory_bytes())
    }

    /// The closest hit with `t` in `(0, ray.tmax]`, ties to the lower triangle id; identical to
    /// [`Bvh::intersect`].
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        with_bvh!(self, bvh => bvh.intersect(ray))
    }

    /// As [`Accel::intersect`], counting nodes and blocks visited into `stats`.
    pub fn intersect_counted(&self, ray: &Ray, stats: &mut TraversalStats) -> Option<Hit> {
        with_bvh!(self, bvh => bvh.intersect_counted(ray, stats))
    }

    /// True if anything lies on the ray with `t` in `(0, ray.tmax]`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        with_bvh!(self, bvh => bvh.occluded(ray))
    }

    /// As [`Accel::intersect`], ignoring the hits `keep(triangle, u, v)` refuses: the closest hit
    /// it accepts (cutout surfaces).
    #[inline]
    pub fn intersect_filtered(&self, ray: &Ray, keep: &dyn Fn(u32, f32, f32) -> bool) -> Option<Hit> {
        with_bvh!(self, bvh => bvh.intersect_filtered(ray, keep))
    }

    /// As [`Accel::occluded`], counting only the hits `keep(triangle, u, v)` accepts.
    #[inline]
    pub fn occluded_filtered(&self, ray: &Ray, keep: &dyn Fn(u32, f32, f32) -> bool) -> bool {
        with_bvh!(self, bvh => bvh.occluded_filtered(ray, keep))
    }

    /// As [`Accel::occluded`], counting nodes and blocks visited into `stats`.
    pub fn occluded_counted(&self, ray: &Ray, stats: &mut TraversalStats) -> bool {
        with_bvh!(self, bvh => bvh.occluded_counted(ray, stats))
    }

    /// Readies `batch` for `rays` rays leaving `origin` inside `region`: gathers their candidate
    /// triangles, or notes that they are cheaper traced one by one (see [`OriginBatch`]).
    #[inline]
    pub fn prepare_batch(&self, batch: &mut OriginBatch, origin: Vec3, region: &Region, rays: u32) {
        with_bvh!(self, bvh => batch.prepare(bvh, origin, region, rays))
    }

    /// Runs `f` compiled for this accel's ISA: code inlined into `f` (pass an `#[inline(always)]`
    /// closure) may use its vector width, e.g. loops over arrays of lanes that the compiler
    /// vectorises. Each lane performs the scalar IEEE operations, so the results do not depend on
    /// the ISA.
    #[inline(always)]
    pub fn simd<R>(&self, f: impl FnOnce() -> R) -> R {
        #[cfg(target_arch = "x86_64")]
        {
            use super::simd::avx::{Avx2, Avx512, AvxLevel};
            match self.bvh {
                // SAFETY: an accel of these ISAs is only built where the CPU supports them (the
                // assertion in `Accel::collapse`).
                IsaBvh::Avx512(_) => return unsafe { Avx512::run(f) },
                // SAFETY: as above.
                IsaBvh::Avx2(_) => return unsafe { Avx2::run(f) },
                _ => {}
            }
        }
        f()
    }

    /// [`Accel::simd`], at most 256 bits wide: AVX2 on both AVX ISAs. For lane loops whose work
    /// measured faster at AVX2 than at AVX-512 on this project's Xeon (the path tracer's vertices).
    #[inline(always)]
    pub fn simd_256<R>(&self, f: impl FnOnce() -> R) -> R {
        #[cfg(target_arch = "x86_64")]
        {
            use super::simd::avx::{Avx2, AvxLevel};
            if let IsaBvh::Avx512(_) | IsaBvh::Avx2(_) = self.bvh {
                // SAFETY: an accel of these ISAs is only built where the CPU supports them, AVX2
                // included (the assertion in `Accel::collapse`).
                return unsafe { Avx2::run(f) };
            }
        }
        f()
    }

    /// Which of the `live` rays (bit `i` for ray `i`) among `N` from the origin of a batch prepared
    /// with [`Accel::prepare_batch`], with the directions `dirs` (SoA) and one `tmax`, are blocked.
    /// The same answers as [`Accel::occluded_in_batch`] ray by ray; bits outside `live` mean nothing.
    #[inline(always)]
    pub fn occluded_lanes_in_batch<const N: usize>(
        &self,
        batch: &OriginBatch,
        dirs: &[[f32; N]; 3],
        tmax: f32,
        live: u32,
    ) -> u32 {
        if !batch.traverses() {
            return batch.occluded_lanes(dirs, tmax);
        }
        // Each thread learns which order of visits answers sooner.
        visit_order::in_learnt_order(
            #[inline(always)]
            |order| self.occluded_from_origin(batch.origin(), dirs, tmax, live, order),
        )
    }

    /// [`WideBvh::occluded_from_origin`]: rays from one point, walked together where they share
    /// nodes, visiting children in `order`. Call it inside [`Accel::simd`], so that its loops over
    /// the rays get the ISA's width.
    #[inline(always)]
    pub fn occluded_from_origin<const N: usize>(
        &self,
        origin: Vec3,
        dirs: &[[f32; N]; 3],
        tmax: f32,
        live: u32,
        order: VisitOrder,
    ) -> u32 {
        with_bvh!(self, bvh => bvh.occluded_from_origin(origin, dirs, tmax, live, order))
    }

    /// [`Accel::occluded`] for a ray of a batch prepared with [`Accel::prepare_batch`].
    #[inline]
    pub fn occluded_in_batch(&self, batch: &OriginBatch, ray: &Ray) -> bool {
        with_bvh!(self, bvh => batch.occluded(bvh, ray))
    }

    /// The closest hits of the `live` rays among `N` (bit `i` for ray `i`; `None` elsewhere), as
    /// [`Accel::intersect`] returns them, traced together: rays that share a [`PacketKey`] (most
    /// of a block of camera rays, or of their shadow rays towards one point) walk the BVH as one
    /// packet, ray-major in this accel's ISA, and the few others alone.
    #[inline(always)]
    pub fn intersect_packet<const N: usize>(&self, rays: &[Ray; N], live: u32) -> [Option<Hit>; N] {
        let mut hits = [None; N];
        let alone = self.for_each_packet(
            rays,
            live,
            #[inline(always)]
            |packet, lanes| {
                let found = with_bvh!(self, bvh => bvh.intersect_packet(packet));
                for lane in lanes_of(lanes) {
                    hits[lane] = found[lane];
                }
            },
        );
        for lane in lanes_of(alone) {
            hits[lane] = self.intersect(&rays[lane]);
        }
        hits
    }

    /// Which of the `live` rays among `N` are blocked (bit `i` for ray `i`), as [`Accel::occluded`]
    /// answers each, traced together as in [`Accel::intersect_packet`].
    #[inline(always)]
    pub fn occluded_packet<const N: usize>(&self, rays: &[Ray; N], live: u32) -> u32 {
        let mut blocked = 0;
        let alone = self.for_each_packet(
            rays,
            live,
            #[inline(always)]
            |packet, lanes| blocked |= with_bvh!(self, bvh => bvh.occluded_packet(packet, lanes)) & lanes,
        );
        for lane in lanes_of(alone) {
            blocked |= u32::from(self.occluded(&rays[lane])) << lane;
        }
        blocked
    }

    /// Splits the `live` rays into groups sharing a key and calls `packet` with each group of at
    /// least `MIN_PACKET_RAYS` (and the group's lanes; the other lanes repeat one of its rays).
    /// Returns the lanes left to trace alone.
    #[inline(always)]
    fn for_each_packet<const N: usize>(
        &self,
        rays: &[Ray; N],
        live: u32,
        mut packet: impl FnMut(&RayPacket<N>, u32),
    ) -> u32 {
        const { assert!(N <= 32, "lane masks are u32") };
        // Plain loops: closures passed to `array::from_fn` or `fold` may be left out of line (a
        // profile showed a call per lane for the keys; the bunny-1m's camera rays took 2% less
        // time without them).
        let mut keys = [PacketKey::ALONE; N];
        for (key, ray) in keys.iter_mut().zip(rays) {
            *key = PacketKey::of(ray);
        }
        let mut alone = 0;
        let mut remaining = live;
        while remaining != 0 {
            let first = remaining.trailing_zeros() as usize;
            let key = keys[first];
            let mut group = 0u32;
            for (lane, &other) in keys.iter().enumerate() {
                group |= u32::from(other == key) << lane;
            }
            group &= remaining;
            remaining &= !group;
            if group.count_ones() < MIN_PACKET_RAYS || key == PacketKey::ALONE {
                alone |= group;
                continue;
            }
            // Lanes outside the group carry the group's first ray, so that every lane shares the key.
            let mut members = *rays;
            for (lane, member) in members.iter_mut().enumerate() {
                if group & (1 << lane) == 0 {
                    *member = rays[first];
                }
            }
            self.simd(
                #[inline(always)]
                || packet(&RayPacket::new(key, &members), group),
            );
        }
        alone
    }
}
