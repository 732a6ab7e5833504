//! Multiple importance sampling weights (Veach 1997, §9.2).

/// Power heuristic with β = 2 for a sample drawn by strategy *a*, when strategy *b* could
/// have drawn it too (Veach 1997, eq. 9.13): p_a² / (p_a² + p_b²). The densities must be in
/// the same measure; a weight that is not finite (both zero, or a density that is) is 0.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let a = pdf_a * pdf_a;
    let b = pdf_b * pdf_b;
    let sum = a + b;
    if sum.is_finite() {
        let w = a / sum;
        if w.is_finite() {
            return w;
        }
    }
    // The squares overflow f32 for densities above ~1.8·10¹⁹ (a light of tiny area seen
    // from afar): such a light would be black. f64 holds them.
    let (a, b) = (pdf_a as f64 * pdf_a as f64, pdf_b as f64 * pdf_b as f64);
    let w = (a / (a + b)) as f32;
    if w.is_finite() { w } else { 0.0 }
}

/// Balance heuristic (Veach 1997, eq. 9.10): p_a / (p_a + p_b).
#[inline]
pub fn balance_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let sum = pdf_a + pdf_b;
    if sum.is_finite() {
        let w = pdf_a / sum;
        if w.is_finite() {
            return w;
        }
    }
    // The sum overflows f32 when both densities are near its limit.
    let w = (pdf_a as f64 / (pdf_a as f64 + pdf_b as f64)) as f32;
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

    #[test]
    fn densities_whose_squares_overflow_f32_keep_their_weight() {
        assert_eq!(power_heuristic(3e19, 0.3), 1.0);
        assert!(power_heuristic(0.3, 3e19) < 1e-30);
        assert_eq!(power_heuristic(3e19, 3e19), 0.5);
        assert_eq!(power_heuristic(1.4e19, 1.4e19), 0.5);
        assert_eq!(balance_heuristic(3e38, 3e38), 0.5);
        assert_eq!(power_heuristic(f32::INFINITY, 1.0), 0.0);
    }
}
