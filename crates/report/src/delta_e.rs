//! Colour differences between two renders, as the page shows them: CIEDE2000 and ΔE_ITP.
//!
//! A pixel's colour is what its PNG shows: the renderer's tone map at exposure 0,
//! d = 1 − exp(−L) per channel (`facet_render::output::film`), kept in f32 rather than rounded to 8 bits,
//! read as linear sRGB (Rec. 709 primaries, D65). Two differences are taken of it:
//!
//! - **ΔE2000**: to CIE L*a*b* (D65), compared by CIEDE2000 (Sharma, Wu & Dalal 2005) — both by
//!   the `palette` crate.
//! - **ΔE_ITP** (ITU-R BT.2124): d to linear BT.2020 RGB (the BT.2087 matrix), display 1.0 at
//!   [`REFERENCE_WHITE`] cd/m², to LMS, PQ-encoded (SMPTE ST 2084), to ICtCp (BT.2100); then
//!   ΔE_ITP = 720 √(ΔI² + ΔT² + ΔP²) with T = ½ Ct, P = Cp. One unit is about one
//!   just-noticeable difference. In f64.
//!
//! Differences are computed only where the pixel sees the sphere (the background is the same in
//! every render).

use facet_render::Image;
use palette::color_difference::Ciede2000;
use palette::{FromColor, Lab, LinSrgb};

/// The luminance of display white (d = 1 in every channel), cd/m², for ΔE_ITP: the HDR
/// reference white of ITU-R BT.2408 (its "graphics white", where SDR white is placed when SDR
/// content is shown in a PQ signal), which ΔE_ITP's absolute scale needs.
pub const REFERENCE_WHITE: f64 = 203.0;

/// Linear Rec. 709 RGB to linear BT.2020 RGB (ITU-R BT.2087, Annex; both D65), rows × column,
/// to 15 digits (derived from the two sets of primaries and D65's chromaticity).
pub const REC709_TO_REC2020: [[f64; 3]; 3] = [
    [0.627403895934699, 0.329283038377884, 0.043313065687417],
    [0.069097289358232, 0.919540395075459, 0.011362315566309],
    [0.016391438875150, 0.088013307877226, 0.895595253247624],
];

/// Linear BT.2020 RGB to LMS (BT.2100, ICtCp), in 4096ths.
const RGB_TO_LMS: [[f64; 3]; 3] = [
    [1688.0, 2146.0, 262.0],
    [683.0, 2951.0, 462.0],
    [99.0, 309.0, 3688.0],
];

/// PQ-encoded L′M′S′ to ICtCp (BT.2100), in 4096ths.
const LMS_TO_ICTCP: [[f64; 3]; 3] = [
    [2048.0, 2048.0, 0.0],
    [6610.0, -13613.0, 7003.0],
    [17933.0, -17390.0, -543.0],
];

/// The PQ signal (SMPTE ST 2084 / BT.2100 inverse EOTF) of a luminance in cd/m² (0 to 10 000).
pub fn pq(luminance: f64) -> f64 {
    const M1: f64 = 2610.0 / 16384.0;
    const M2: f64 = 2523.0 / 4096.0 * 128.0;
    const C1: f64 = 3424.0 / 4096.0;
    const C2: f64 = 2413.0 / 4096.0 * 32.0;
    const C3: f64 = 2392.0 / 4096.0 * 32.0;
    let y = (luminance.max(0.0) / 10_000.0).powf(M1);
    ((C1 + C2 * y) / (1.0 + C3 * y)).powf(M2)
}

fn apply(m: &[[f64; 3]; 3], v: [f64; 3], scale: f64) -> [f64; 3] {
    m.map(|row| scale * (row[0] * v[0] + row[1] * v[1] + row[2] * v[2]))
}

/// ICtCp (BT.2100, PQ) of a displayed colour, display 1.0 at [`REFERENCE_WHITE`] cd/m².
pub fn ictcp(c: LinSrgb) -> [f64; 3] {
    let rgb = [c.red, c.green, c.blue].map(f64::from);
    let bt2020 = apply(&REC709_TO_REC2020, rgb, REFERENCE_WHITE);
    let lms = apply(&RGB_TO_LMS, bt2020, 1.0 / 4096.0).map(pq);
    apply(&LMS_TO_ICTCP, lms, 1.0 / 4096.0)
}

/// ΔE_ITP (ITU-R BT.2124) between two ICtCp colours.
pub fn delta_e_itp(a: [f64; 3], b: [f64; 3]) -> f64 {
    let (di, dt, dp) = (a[0] - b[0], 0.5 * (a[1] - b[1]), a[2] - b[2]);
    720.0 * (di * di + dt * dt + dp * dp).sqrt()
}

/// The two colour differences of one comparison (of a pixel, or means).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DePair<T> {
    /// CIEDE2000.
    pub de2000: T,
    /// ΔE_ITP (BT.2124).
    pub itp: T,
}

impl<T: Copy> DePair<T> {
    /// The two in the page's order ([`NAMES`]).
    pub fn both(self) -> [T; 2] {
        [self.de2000, self.itp]
    }
}

/// The differences' names on the page, in [`DePair::both`]'s order.
pub const NAMES: [&str; 2] = ["ΔE2000", "ΔE_ITP"];

/// A per-pixel ΔE image, `None` off the sphere.
pub struct DeltaE {
    pub width: u32,
    pub height: u32,
    pub values: Vec<Option<DePair<f32>>>,
}

/// The displayed colour of a linear radiance: the PNG's tone map at exposure 0, unrounded.
pub fn displayed(radiance: [f32; 3]) -> LinSrgb {
    // d = 1 − exp(−L): facet_render::output::film's tone map, before its sRGB encoding.
    let d = radiance.map(|v| 1.0 - (-v.max(0.0)).exp());
    LinSrgb::new(d[0], d[1], d[2])
}

/// CIE L*a*b* (D65) of a displayed colour.
pub fn lab(c: LinSrgb) -> Lab {
    Lab::from_color(c)
}

/// CIEDE2000 ΔE between two L*a*b* colours.
pub fn ciede2000(a: Lab, b: Lab) -> f32 {
    a.difference(b)
}

/// Both differences between two displayed colours.
pub fn differences(a: LinSrgb, b: LinSrgb) -> DePair<f32> {
    DePair {
        de2000: ciede2000(lab(a), lab(b)),
        itp: delta_e_itp(ictcp(a), ictcp(b)) as f32,
    }
}

/// ΔE per pixel of `test` against `reference` where `mask(x, y)` holds.
pub fn delta_e_image(reference: &Image, test: &Image, mask: &impl Fn(u32, u32) -> bool) -> DeltaE {
    assert_eq!(
        (reference.width, reference.height),
        (test.width, test.height),
        "ΔE of images of different sizes"
    );
    let w = reference.width;
    let values = (reference.pixels.iter().zip(&test.pixels))
        .enumerate()
        .map(|(i, (r, t))| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            mask(x, y).then(|| differences(displayed(*r), displayed(*t)))
        })
        .collect();
    DeltaE {
        width: w,
        height: reference.height,
        values,
    }
}

impl DeltaE {
    /// The mean of each difference over the pixels that have one (0 when none has).
    pub fn mean(&self) -> DePair<f64> {
        let (sum, n) =
            self.values
                .iter()
                .flatten()
                .fold((DePair::<f64>::default(), 0usize), |(s, n), v| {
                    let sum = DePair {
                        de2000: s.de2000 + v.de2000 as f64,
                        itp: s.itp + v.itp as f64,
                    };
                    (sum, n + 1)
                });
        let n = n.max(1) as f64;
        DePair {
            de2000: sum.de2000 / n,
            itp: sum.itp / n,
        }
    }

    /// The per-pixel mean of several ΔE images of one size (a pixel with none in any is none).
    pub fn mean_of(images: &[&DeltaE]) -> Option<DeltaE> {
        let first = images.first()?;
        let n = images.len() as f64;
        let values = (0..first.values.len())
            .map(|i| {
                let (mut de2000, mut itp) = (0.0f64, 0.0f64);
                for im in images {
                    let v = im.values.get(i).copied().flatten()?;
                    de2000 += v.de2000 as f64;
                    itp += v.itp as f64;
                }
                Some(DePair {
                    de2000: (de2000 / n) as f32,
                    itp: (itp / n) as f32,
                })
            })
            .collect();
        Some(DeltaE {
            width: first.width,
            height: first.height,
            values,
        })
    }
}
