//! Multiple importance sampling weights (Veach 1997, §9.2).

/// Power heuristic with β = 2 for a sample drawn by strategy *a*, when strategy *b* could
/// have drawn it too (Veach 1997, eq. 9.13): p_a² / (p_a² + p_b²). The densities must be in
/// the same measure; a weight that is not finite (both zero, or an overflow) is 0.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let a = pdf_a * pdf_a;
    let b = pdf_b * pdf_b;
    let w = a / (a + b);
    if w.is_finite() { w } else { 0.0 }
}

/// Balance heuristic (Veach 1997, eq. 9.10): p_a / (p_a + p_b).
#[inline]
pub fn balance_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let w = pdf_a / (pdf_a + pdf_b);
    if w.is_finite() { w } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_of_two_strategies_sum_to_one() {
        for (a, b) in [(1.0, 3.0), (0.2, 0.0), (5.0, 5.0), (1e-20, 1e-3)] {
            assert!((power_heuristic(a, b) + power_heuristic(b, a) - 1.0).abs() < 1e-6);
            assert!((balance_heuristic(a, b) + balance_heuristic(b, a) - 1.0).abs() < 1e-6);
        }
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(2.0, 0.0), 1.0);
        assert_eq!(balance_heuristic(1.0, 3.0), 0.25);
        assert_eq!(power_heuristic(1.0, 3.0), 0.1);
    }
}
