//! What the binary and the wide traversals share so that they visit the same boxes and agree bit for
//! bit: the conservative slab expansion, the pruning slack and the reciprocal of a direction.

/// Slab test expansion that makes the f32 box test conservative: `1 + 2 * gamma(3)` (Ize, "Robust BVH
/// Ray Traversal", JCGT 2013), so a ray that hits a triangle never misses that triangle's box.
pub(super) const BOX_EXPANSION: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Slack on the "is this box closer than the best hit?" test. A box entry distance and a triangle's
/// `t` are rounded differently; without slack, a box whose triangle lies at exactly the best `t`
/// (a ray through a shared edge or vertex) could be pruned, and the lower-id tie-break would then
/// depend on the visiting order. About 32 ulps: it costs nothing measurable.
pub(super) const PRUNE_SLACK: f32 = 1.0 + 1.0 / (1 << 18) as f32;

/// `1 / d`, but a huge finite value instead of infinity for a zero direction component, so that
/// `(plane - origin) * inv_dir` is 0, not NaN, for an origin lying on a slab plane.
#[inline]
pub(super) fn safe_reciprocal(d: f32) -> f32 {
    if d.abs() < 1e-30 { 1e30f32.copysign(d) } else { 1.0 / d }
}
