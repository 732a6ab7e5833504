//! Spectra to RGB as Mitsuba 3's RGB variants do it, and named IORs and metals
//! (../shared/MITSUBA-NOTES.md, "Spectra in RGB mode").

use crate::math::Rgb;

/// What a spectrum describes; it decides the white point and the clamping.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumUse {
    /// A reflectance or transmittance: weighted by D65, clamped to [0, 1].
    Reflectance,
    /// Emitted radiance or intensity: not D65-weighted, negatives clamped to 0.
    Emission,
    /// A physical quantity such as η or k: not weighted, not clamped above.
    Unbounded,
}

/// Converts a piecewise-linear spectrum given as (wavelength nm, value) pairs, sorted by
/// wavelength, to linear sRGB.
pub fn spectrum_to_rgb(pairs: &[(f32, f32)], usage: SpectrumUse) -> Rgb {
    let _ = (pairs, usage);
    todo!("spectra")
}

/// A named index of refraction (`bk7`, `water`, `air`, `diamond`, `vacuum`, …).
pub fn named_ior(name: &str) -> Option<f32> {
    let _ = name;
    todo!("spectra")
}

/// A named conductor's complex IOR (η, k) in RGB (`Au`, `Ag`, `Cu`, `Al`, …).
pub fn named_conductor(name: &str) -> Option<(Rgb, Rgb)> {
    let _ = name;
    todo!("spectra")
}
