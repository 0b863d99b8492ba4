//! Multiple importance sampling weights (Veach 1997, ch. 9).

/// The power heuristic with β = 2 for a sample drawn with density `pdf_a` by one technique, against
/// another technique of density `pdf_b` for the same point (one sample each, both densities in the
/// same measure): `pdf_a² / (pdf_a² + pdf_b²)`, computed as a ratio so that large densities do not
/// overflow. 0 when `pdf_a` is 0; 1 when `pdf_a` is infinite (a delta lobe takes all the weight).
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    if pdf_a.is_nan() || pdf_a <= 0.0 {
        return 0.0;
    }
    let ratio = pdf_b / pdf_a;
    1.0 / (1.0 + ratio * ratio)
}
