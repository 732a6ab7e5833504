//! A pixel's photon-mapping statistics and their progressive update (Hachisuka et al.
//! 2008, §4.2): the accumulated photon count N, the radius R and the flux τ.

use crate::math::Rgb;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStatistics {
    /// N: photons accumulated, with the share α of each pass's kept.
    pub n: f64,
    /// R: the gather radius; 0 until the pixel's first hit point sets it.
    pub radius: f64,
    /// τ: Σ β_eye·f·Φ over the photons gathered, rescaled as R shrinks.
    pub tau: [f64; 3],
    /// The emission the pixel's eye paths met, summed over passes.
    pub emitted: [f64; 3],
}

impl PixelStatistics {
    /// Adds a pass that found `m` photons carrying `flux` within the radius:
    /// N' = N + αM, R' = R·√((N + αM)/(N + M)), τ' = (τ + Φ)·(R'/R)² (eqs. 7, 11, 12).
    /// A pass without photons changes nothing.
    pub fn progress(&mut self, alpha: f64, m: u64, flux: [f64; 3]) {
        if m == 0 {
            return;
        }
        let m = m as f64;
        let n_new = self.n + alpha * m;
        let shrink = n_new / (self.n + m);
        self.n = n_new;
        self.radius *= shrink.sqrt();
        for (tau, flux) in self.tau.iter_mut().zip(flux) {
            *tau = (*tau + flux) * shrink;
        }
    }

    pub fn add_emitted(&mut self, value: Rgb) {
        for (sum, v) in self.emitted.iter_mut().zip(value.0) {
            *sum += v as f64;
        }
    }

    /// The pixel's estimate: τ/(πR²·N_emitted) plus the mean emission over `passes`.
    pub fn radiance(&self, light_paths: u64, passes: f64) -> Rgb {
        let area = std::f64::consts::PI * self.radius * self.radius;
        let gathered = if area > 0.0 && light_paths > 0 {
            1.0 / (area * light_paths as f64)
        } else {
            0.0
        };
        Rgb(std::array::from_fn(|c| {
            (self.tau[c] * gathered + self.emitted[c] / passes) as f32
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With M photons every pass, N_k = αMk and R_k² = R_0²·Π_{i<k} α(i + 1)/(αi + 1): the
    /// closed form of the schedule. And τ_k/R_k² = Σ_i Φ_i/R_i², R_i the radius pass i
    /// gathered with: every pass's flux keeps its own density.
    #[test]
    fn the_radius_schedule_follows_the_formula() {
        for alpha in [0.5, 2.0 / 3.0, 0.8] {
            let m = 40u64;
            let r0 = 0.25;
            let mut s = PixelStatistics {
                radius: r0,
                ..Default::default()
            };
            let mut density = 0.0;
            let mut product = 1.0;
            for k in 0..200 {
                let flux = 3.0 + (k % 7) as f64;
                density += flux / (s.radius * s.radius);
                s.progress(alpha, m, [flux, 2.0 * flux, 0.0]);
                product *= alpha * (k as f64 + 1.0) / (alpha * k as f64 + 1.0);
                let expected_r2 = r0 * r0 * product;
                assert!(
                    (s.radius * s.radius / expected_r2 - 1.0).abs() < 1e-12,
                    "α {alpha}, pass {k}"
                );
                assert!((s.n - alpha * m as f64 * (k + 1) as f64).abs() < 1e-9);
                let r2 = s.radius * s.radius;
                assert!((s.tau[0] / r2 / density - 1.0).abs() < 1e-12);
                assert!((s.tau[1] / r2 / density - 2.0).abs() < 2e-12);
                assert_eq!(s.tau[2], 0.0);
            }
            // With the same M every pass each factor is α(k + 1)/(αk + 1) ≈ 1 − (1/α − 1)/k,
            // so R² falls as k^−(1−α)/α: the last hundred passes' log-log slope. (In a
            // real gather M shrinks with R², which gives Knaus and Zwicker's N^(α−1).)
            let at = |k: f64| -> f64 {
                (0..k as usize).fold(1.0, |p, i| {
                    p * alpha * (i as f64 + 1.0) / (alpha * i as f64 + 1.0)
                })
            };
            let slope = (at(200.0) / at(100.0)).ln() / 2f64.ln();
            let expected = -(1.0 - alpha) / alpha;
            assert!((slope - expected).abs() < 0.02, "α {alpha}: slope {slope}");
        }
    }

    /// A pass that finds no photon leaves N, R and τ; emission is averaged over passes.
    #[test]
    fn empty_passes_change_nothing_and_emission_averages() {
        let mut s = PixelStatistics {
            radius: 0.5,
            ..Default::default()
        };
        s.progress(0.7, 10, [1.0; 3]);
        let before = s;
        s.progress(0.7, 0, [0.0; 3]);
        assert_eq!(s, before);
        s.add_emitted(Rgb([2.0, 4.0, 6.0]));
        s.add_emitted(Rgb([0.0; 3]));
        let with_emission = s.radiance(100, 2.0);
        let without = PixelStatistics {
            emitted: [0.0; 3],
            ..s
        }
        .radiance(100, 2.0);
        assert!((with_emission.0[1] - without.0[1] - 2.0).abs() < 1e-6);
    }
}
