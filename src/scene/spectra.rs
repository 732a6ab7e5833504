//! Spectra to RGB as Mitsuba 3's RGB variants do it, and named IORs and metals
//! (../shared/MITSUBA-NOTES.md, "Spectra in RGB mode").
//!
//! A spectrum given as (wavelength, value) pairs is a piecewise-linear function, zero outside
//! its first and last wavelength. It is integrated against the CIE 1931 colour matching
//! functions (optionally times the D65 illuminant) with Mitsuba 3's quadrature: 1000 evenly
//! spaced wavelengths from 360 to 830 nm inclusive, the tables interpolated linearly between
//! their 5 nm samples. XYZ is normalised so that a unit spectrum has luminance Y = 1 under the
//! same quadrature, then converted to linear sRGB and clamped as the usage says.

use super::cie_tables::{self as cie, SAMPLES};
use crate::math::Rgb;

/// What a spectrum describes; it decides the white point and the clamping, following how
/// Mitsuba 3's scene parser treats a `<spectrum>` by where it appears.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumUse {
    /// A reflectance or transmittance (any `<spectrum>` outside an emitter other than the
    /// ones below): weighted by D65, clamped to [0, 1].
    Reflectance,
    /// Emitted radiance or intensity (a `<spectrum>` inside an `<emitter>`): not weighted by
    /// D65, negatives clamped to 0, not clamped above. A constant spectrum therefore becomes
    /// the sRGB colour of the equal-energy white E, about (1.205, 0.948, 0.909) times it.
    /// Mitsuba converts the spectral data of its named conductors the same way.
    Emission,
    /// A physical quantity that may exceed 1: a `<spectrum>` named `eta`, `k`, `int_ior`,
    /// `ext_ior` or `sigma_t` outside an emitter. Mitsuba 3 weights these by D65 like a
    /// reflectance, clamps negatives to 0 and does not clamp above.
    Unbounded,
}

/// Number of wavelengths of the integration, evenly spaced over [360, 830] nm inclusive.
const INTEGRATION_STEPS: usize = 1000;

/// The D65 table is divided by this before weighting. It is the factor Mitsuba 3 uses
/// (measured: Mitsuba 3.9.1 turns a constant reflectance of 1 into (0.998985, 0.998874,
/// 0.998802), and so does this code). It is 0.11 % larger than the ∫ȳ·D65 / ∫ȳ of the
/// quadrature itself (98.888), which is why a constant reflectance c comes out as 0.9989 c
/// rather than c; matching Mitsuba matters more here than the round number.
const D65_NORMALIZATION: f64 = 98.997_417_518_762_55;

/// CIE XYZ to linear sRGB: ITU-R BT.709 primaries, D65 white.
const XYZ_TO_LINEAR_SRGB: [[f64; 3]; 3] = [
    [3.240479, -1.537150, -0.498535],
    [-0.969256, 1.875991, 0.041556],
    [0.055648, -0.204043, 1.057311],
];

/// A 5 nm table at `wavelength`, linearly interpolated, zero outside 360–830 nm.
fn table_at(table: &[f64; SAMPLES], wavelength: f64) -> f64 {
    if !(cie::MIN_WAVELENGTH..=cie::MAX_WAVELENGTH).contains(&wavelength) {
        return 0.0;
    }
    let t = (wavelength - cie::MIN_WAVELENGTH) * ((SAMPLES - 1) as f64)
        / (cie::MAX_WAVELENGTH - cie::MIN_WAVELENGTH);
    let i = (t as usize).min(SAMPLES - 2);
    let f = t - i as f64;
    (1.0 - f) * table[i] + f * table[i + 1]
}

/// The i-th integration wavelength.
fn integration_wavelength(i: usize) -> f64 {
    cie::MIN_WAVELENGTH
        + (i as f64 / (INTEGRATION_STEPS - 1) as f64) * (cie::MAX_WAVELENGTH - cie::MIN_WAVELENGTH)
}

/// The piecewise-linear spectrum at `w` (which lies within the first and last wavelength).
fn spectrum_at(pairs: &[(f32, f32)], w: f64) -> f64 {
    // The last interval whose start is at or below w.
    let i = pairs
        .partition_point(|p| p.0 as f64 <= w)
        .saturating_sub(1)
        .min(pairs.len() - 2);
    let (w0, v0) = (pairs[i].0 as f64, pairs[i].1 as f64);
    let (w1, v1) = (pairs[i + 1].0 as f64, pairs[i + 1].1 as f64);
    if w1 <= w0 {
        return v1;
    }
    v0 + (v1 - v0) * (w - w0) / (w1 - w0)
}

/// CIE XYZ of a spectrum, optionally as seen under D65, normalised so that a unit spectrum
/// (without D65) has Y = 1.
fn spectrum_to_xyz(pairs: &[(f32, f32)], d65: bool) -> [f64; 3] {
    let mut xyz = [0.0f64; 3];
    let mut y_total = 0.0f64;
    let (first, last) = match pairs {
        [first, .., last] => (first.0 as f64, last.0 as f64),
        _ => return xyz,
    };
    for i in 0..INTEGRATION_STEPS {
        let w = integration_wavelength(i);
        let y_bar = table_at(&cie::CIE_1931_Y, w);
        y_total += y_bar;
        if w < first || w > last {
            continue;
        }
        let mut v = spectrum_at(pairs, w);
        if d65 {
            v *= table_at(&cie::D65, w) / D65_NORMALIZATION;
        }
        xyz[0] += v * table_at(&cie::CIE_1931_X, w);
        xyz[1] += v * y_bar;
        xyz[2] += v * table_at(&cie::CIE_1931_Z, w);
    }
    xyz.map(|c| c / y_total)
}

fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    XYZ_TO_LINEAR_SRGB.map(|row| row[0] * xyz[0] + row[1] * xyz[1] + row[2] * xyz[2])
}

/// Clamps as the usage says (NaN becomes 0).
fn clamp_for(usage: SpectrumUse, rgb: [f64; 3]) -> Rgb {
    let clamp = |c: f64| match usage {
        _ if c.is_nan() => 0.0,
        SpectrumUse::Reflectance => c.clamp(0.0, 1.0),
        SpectrumUse::Emission | SpectrumUse::Unbounded => c.max(0.0),
    };
    let [r, g, b] = rgb.map(|c| clamp(c) as f32);
    Rgb::new(r, g, b)
}

/// Converts a piecewise-linear spectrum given as (wavelength nm, value) pairs, sorted by
/// wavelength, to linear sRGB. The caller checks that the values are finite and the
/// wavelengths ascending; fewer than two pairs describe no extent and give black.
pub fn spectrum_to_rgb(pairs: &[(f32, f32)], usage: SpectrumUse) -> Rgb {
    let xyz = spectrum_to_xyz(pairs, usage != SpectrumUse::Emission);
    clamp_for(usage, xyz_to_linear_srgb(xyz))
}

/// A constant spectrum (a `<spectrum>` with a single value) in linear sRGB, as Mitsuba 3's
/// RGB variants read it: the value itself, except inside an emitter, where it is the
/// equal-energy spectrum seen without D65 adaptation, value × M·(1, 1, 1) for the XYZ to
/// sRGB matrix M (about (1.205, 0.948, 0.909) × value).
pub fn uniform_spectrum_to_rgb(value: f32, usage: SpectrumUse) -> Rgb {
    match usage {
        SpectrumUse::Emission => {
            let v = value as f64;
            clamp_for(usage, xyz_to_linear_srgb([v, v, v]))
        }
        SpectrumUse::Reflectance | SpectrumUse::Unbounded => Rgb::splat(value),
    }
}

/// Named indices of refraction (the table Mitsuba 3 and pbrt share), matched without regard
/// to case as Mitsuba does.
const NAMED_IORS: [(&str, f32); 23] = [
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// A named index of refraction (`bk7`, `water`, `air`, `diamond`, `vacuum`, …).
pub fn named_ior(name: &str) -> Option<f32> {
    NAMED_IORS
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|&(_, ior)| ior)
}

/// Mitsuba 3's named conductors: (name, η, k), linear sRGB as Mitsuba 3's RGB mode derives
/// them from its spectral data (the `data/ior/<name>.eta.spd` and `.k.spd` files of the
/// Mitsuba 3.9.1 wheel, converted like an emitted spectrum: no D65, negatives clamped to 0).
/// Read from Mitsuba 3.9.1 `scalar_rgb` by experiments/tools/spectra_reference.py
/// (`conductors`); tests/spectra.rs can recompute them from the spectral files.
const NAMED_CONDUCTORS: [(&str, [f32; 3], [f32; 3]); 71] = [
    (
        "Ag",
        [0.1552762, 0.116727956, 0.13838764],
        [4.8283544, 3.1222224, 2.1469011],
    ),
    (
        "Al",
        [1.6575009, 0.8804047, 0.52124447],
        [9.223811, 6.269502, 4.837004],
    ),
    (
        "AlAs",
        [3.605296, 3.2329378, 2.2163186],
        [0.0006794373, 0.0, 0.007512709],
    ),
    (
        "AlAs_palik",
        [3.605296, 3.2329378, 2.2163186],
        [0.0006794373, 0.0, 0.007512709],
    ),
    (
        "AlSb",
        [0.0, 4.1393747, 4.6692543],
        [0.0, 0.09400908, 1.30057],
    ),
    (
        "AlSb_palik",
        [0.0, 4.1393747, 4.6692543],
        [0.0, 0.09400908, 1.30057],
    ),
    (
        "Au",
        [0.14303598, 0.37530708, 1.4420453],
        [3.982997, 2.3855565, 1.6033592],
    ),
    (
        "Be",
        [4.1850123, 3.1850293, 2.7840612],
        [3.835466, 3.0101223, 2.868994],
    ),
    (
        "Be_palik",
        [4.1850123, 3.1850293, 2.7840612],
        [3.835466, 3.0101223, 2.868994],
    ),
    (
        "Cr",
        [4.3696675, 2.9165053, 1.6549046],
        [5.206547, 4.231306, 3.7546988],
    ),
    ("CsI", [2.1448996, 1.7023189, 1.6624272], [0.0, 0.0, 0.0]),
    (
        "CsI_palik",
        [2.1448996, 1.7023189, 1.6624272],
        [0.0, 0.0, 0.0],
    ),
    (
        "Cu",
        [0.20100547, 0.9237495, 1.1022154],
        [3.9132621, 2.4530451, 2.1420898],
    ),
    (
        "Cu2O",
        [3.5517726, 2.9498696, 2.7518754],
        [0.11420702, 0.19389686, 0.6061339],
    ),
    (
        "Cu2O_palik",
        [3.5517726, 2.9498696, 2.7518754],
        [0.11420702, 0.19389686, 0.6061339],
    ),
    (
        "CuO",
        [3.247541, 2.4478052, 2.2102196],
        [0.52108955, 0.57003075, 0.72217894],
    ),
    (
        "CuO_palik",
        [3.247541, 2.4478052, 2.2102196],
        [0.52108955, 0.57003075, 0.72217894],
    ),
    (
        "Cu_palik",
        [0.21322851, 0.9197154, 1.1024108],
        [3.9218733, 2.4573317, 2.136584],
    ),
    (
        "Hg",
        [2.3989387, 1.440028, 0.9095704],
        [6.327587, 4.371925, 3.4217637],
    ),
    (
        "HgTe",
        [4.77904, 3.2311962, 2.6599011],
        [1.6316127, 1.5808104, 1.7292874],
    ),
    (
        "HgTe_palik",
        [4.77904, 3.2311962, 2.6599011],
        [1.6316127, 1.5808104, 1.7292874],
    ),
    (
        "Hg_palik",
        [2.3989387, 1.440028, 0.9095704],
        [6.327587, 4.371925, 3.4217637],
    ),
    (
        "Ir",
        [3.0863, 2.0821905, 1.6179146],
        [5.592153, 4.067088, 3.267312],
    ),
    (
        "Ir_palik",
        [3.0863, 2.0821905, 1.6179146],
        [5.592153, 4.067088, 3.267312],
    ),
    (
        "K",
        [0.06404319, 0.046409767, 0.038184915],
        [2.1041996, 1.34894, 0.9131259],
    ),
    (
        "K_palik",
        [0.06404319, 0.046409767, 0.038184915],
        [2.1041996, 1.34894, 0.9131259],
    ),
    (
        "Li",
        [0.26579094, 0.19561832, 0.22094862],
        [3.540155, 2.3111234, 1.6686072],
    ),
    (
        "Li_palik",
        [0.26579094, 0.19561832, 0.22094862],
        [3.540155, 2.3111234, 1.6686072],
    ),
    (
        "MgO",
        [2.0895839, 1.6507235, 1.594879],
        [4.3326952e-12, 0.0, 2.4986457e-11],
    ),
    (
        "MgO_palik",
        [2.0895839, 1.6507235, 1.594879],
        [4.3326952e-12, 0.0, 2.4986457e-11],
    ),
    (
        "Mo",
        [4.483974, 3.5251307, 2.7763104],
        [4.1114373, 3.420827, 3.1506073],
    ),
    (
        "Mo_palik",
        [4.483974, 3.5251307, 2.7763104],
        [4.1114373, 3.420827, 3.1506073],
    ),
    (
        "Na_palik",
        [0.060269356, 0.056140948, 0.061988432],
        [3.1792734, 2.1124904, 1.5790411],
    ),
    (
        "Nb",
        [3.420074, 2.7900932, 2.3956294],
        [3.4413946, 2.7376661, 2.5797458],
    ),
    (
        "Nb_palik",
        [3.420074, 2.7900932, 2.3956294],
        [3.4413946, 2.7376661, 2.5797458],
    ),
    (
        "Ni_palik",
        [2.3673046, 1.6633731, 1.4670781],
        [4.4988117, 3.050153, 2.3454392],
    ),
    (
        "Rh",
        [2.5857935, 1.8602164, 1.5542634],
        [6.7822604, 4.702987, 3.976073],
    ),
    (
        "Rh_palik",
        [2.5857935, 1.8602164, 1.5542634],
        [6.7822604, 4.702987, 3.976073],
    ),
    (
        "Se",
        [4.0583115, 2.842935, 2.8208535],
        [0.75404954, 0.6384435, 0.52180755],
    ),
    (
        "Se-e",
        [5.722849, 4.165736, 4.0813384],
        [0.8711363, 1.1051575, 1.5653203],
    ),
    (
        "Se-e_palik",
        [5.722849, 4.165736, 4.0813384],
        [0.8711363, 1.1051575, 1.5653203],
    ),
    (
        "Se_palik",
        [4.0583115, 2.842935, 2.8208535],
        [0.75404954, 0.6384435, 0.52180755],
    ),
    (
        "SiC",
        [3.1723416, 2.5259717, 2.4793706],
        [7.5376636e-07, 0.0, 1.0192531e-05],
    ),
    (
        "SiC_palik",
        [3.1723416, 2.5259717, 2.4793706],
        [7.5376636e-07, 0.0, 1.0192531e-05],
    ),
    ("SnTe", [4.5242496, 1.981645, 1.2815913], [0.0, 0.0, 0.0]),
    (
        "SnTe_palik",
        [4.5242496, 1.981645, 1.2815913],
        [0.0, 0.0, 0.0],
    ),
    (
        "Ta",
        [2.062721, 2.3929389, 2.6279287],
        [2.4083598, 1.7414864, 1.9470278],
    ),
    (
        "Ta_palik",
        [2.062721, 2.3929389, 2.6279287],
        [2.4083598, 1.7414864, 1.9470278],
    ),
    (
        "Te",
        [7.3902335, 4.482105, 2.637106],
        [3.2560222, 3.5270588, 3.2920542],
    ),
    (
        "Te-e",
        [7.508907, 4.2964287, 2.3699877],
        [5.5839286, 4.947205, 3.9975922],
    ),
    (
        "Te-e_palik",
        [7.508907, 4.2964287, 2.3699877],
        [5.5839286, 4.947205, 3.9975922],
    ),
    (
        "Te_palik",
        [7.3902335, 4.482105, 2.637106],
        [3.2560222, 3.5270588, 3.2920542],
    ),
    ("ThF4", [1.8307136, 1.4422286, 1.3876476], [0.0, 0.0, 0.0]),
    (
        "ThF4_palik",
        [1.8307136, 1.4422286, 1.3876476],
        [0.0, 0.0, 0.0],
    ),
    (
        "TiC",
        [3.7005284, 2.8374221, 2.582287],
        [3.265635, 2.3515892, 2.1727905],
    ),
    (
        "TiC_palik",
        [3.7005284, 2.8374221, 2.582287],
        [3.265635, 2.3515892, 2.1727905],
    ),
    (
        "TiN",
        [1.6484497, 1.150516, 1.3798234],
        [3.368328, 1.9434981, 1.1020677],
    ),
    (
        "TiN_palik",
        [1.6484497, 1.150516, 1.3798234],
        [3.368328, 1.9434981, 1.1020677],
    ),
    (
        "TiO2",
        [3.45661, 2.8017359, 2.905175],
        [0.00010526484, 0.0, 0.0006528865],
    ),
    (
        "TiO2-e",
        [3.1065645, 2.5131683, 2.5824444],
        [2.9751605e-05, 0.0, 0.00018269809],
    ),
    (
        "TiO2-e_palik",
        [3.1065645, 2.5131683, 2.5824444],
        [2.9751605e-05, 0.0, 0.00018269809],
    ),
    (
        "TiO2_palik",
        [3.45661, 2.8017359, 2.905175],
        [0.00010526484, 0.0, 0.0006528865],
    ),
    (
        "VC",
        [3.657566, 2.752736, 2.532672],
        [3.0683007, 2.1986873, 1.9631927],
    ),
    (
        "VC_palik",
        [3.657566, 2.752736, 2.532672],
        [3.0683007, 2.1986873, 1.9631927],
    ),
    (
        "VN",
        [2.8656023, 2.119189, 1.9400911],
        [3.0322425, 2.0561156, 1.6163063],
    ),
    (
        "VN_palik",
        [2.8656023, 2.119189, 1.9400911],
        [3.0322425, 2.0561156, 1.6163063],
    ),
    (
        "V_palik",
        [4.277582, 3.5129488, 2.7610714],
        [3.4913008, 2.8894548, 3.111522],
    ),
    (
        "W",
        [4.3708167, 3.3002465, 2.9984074],
        [3.5006406, 2.604874, 2.2732332],
    ),
    (
        "a-C",
        [2.9440458, 2.2271364, 1.9681617],
        [0.8874649, 0.7992985, 0.81529],
    ),
    ("d-C", [2.7087197, 2.3188257, 2.2288976], [0.0, 0.0, 0.0]),
    (
        "d-C_palik",
        [2.7087197, 2.3188257, 2.2288976],
        [0.0, 0.0, 0.0],
    ),
];

/// A named conductor's complex IOR (η, k) in RGB (`Au`, `Ag`, `Cu`, `Al`, …), with Mitsuba 3's
/// names (case-sensitive, as Mitsuba's file lookup is). `none` (Mitsuba's perfect mirror) is
/// not a conductor here: the caller handles it.
pub fn named_conductor(name: &str) -> Option<(Rgb, Rgb)> {
    NAMED_CONDUCTORS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|&(_, eta, k)| (Rgb(eta), Rgb(k)))
}

/// Every named conductor, for messages that list the valid names.
pub fn conductor_names() -> impl Iterator<Item = &'static str> {
    NAMED_CONDUCTORS.iter().map(|(n, _, _)| *n)
}

/// Every named IOR, for messages that list the valid names.
pub fn ior_names() -> impl Iterator<Item = &'static str> {
    NAMED_IORS.iter().map(|(n, _)| *n)
}
