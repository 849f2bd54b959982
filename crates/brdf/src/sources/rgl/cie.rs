//! Spectra to linear Rec.709 RGB through the CIE 1931 colour matching functions.
//!
//! A reflectance spectrum S(λ) (the value at the file's wavelengths, linear between them and
//! constant beyond the ends) is integrated under the CIE D65 illuminant,
//! X = ∫ S x̄ D65 dλ / ∫ ȳ D65 dλ (and Y, Z alike), by the trapezoidal rule on the tables'
//! 5 nm nodes from 360 to 780 nm, then taken to linear Rec.709 (D65 white) by the sRGB matrix
//! (IEC 61966-2-1). A constant spectrum of 1 gives RGB (1, 1, 1) within the tables'
//! rounding. The conversion is linear in S, so it is a 3 × n matrix applied to each spectrum.

/// CIE 1931 2° observer x̄, ȳ, z̄ and the CIE D65 relative spectral power at 360, 365, …,
/// 780 nm (CIE 015:2018 tables at 5 nm). Beyond 780 nm the matching functions are below
/// 10⁻⁴ of their peaks.
const CIE_5NM: [[f64; 4]; 85] = [
    [0.0001299, 3.917e-06, 0.0006061, 46.6383],
    [0.0002321, 6.965e-06, 0.001086, 49.3637],
    [0.0004149, 1.239e-05, 0.001946, 52.0891],
    [0.0007416, 2.202e-05, 0.003486, 51.0323],
    [0.001368, 3.9e-05, 0.006450001, 49.9755],
    [0.002236, 6.4e-05, 0.01054999, 52.3118],
    [0.004243, 0.00012, 0.02005001, 54.6482],
    [0.00765, 0.000217, 0.03621, 68.7015],
    [0.01431, 0.000396, 0.06785001, 82.7549],
    [0.02319, 0.00064, 0.1102, 87.1204],
    [0.04351, 0.00121, 0.2074, 91.486],
    [0.07763, 0.00218, 0.3713, 92.4589],
    [0.13438, 0.004, 0.6456, 93.4318],
    [0.21477, 0.0073, 1.0390501, 90.057],
    [0.2839, 0.0116, 1.3856, 86.6823],
    [0.3285, 0.01684, 1.62296, 95.7736],
    [0.34828, 0.023, 1.74706, 104.865],
    [0.34806, 0.0298, 1.7826, 110.936],
    [0.3362, 0.038, 1.77211, 117.008],
    [0.3187, 0.048, 1.7441, 117.41],
    [0.2908, 0.06, 1.6692, 117.812],
    [0.2511, 0.0739, 1.5281, 116.336],
    [0.19536, 0.09098, 1.28764, 114.861],
    [0.1421, 0.1126, 1.0419, 115.392],
    [0.09564, 0.13902, 0.8129501, 115.923],
    [0.05795001, 0.1693, 0.6162, 112.367],
    [0.03201, 0.20802, 0.46518, 108.811],
    [0.0147, 0.2586, 0.3533, 109.082],
    [0.0049, 0.323, 0.272, 109.354],
    [0.0024, 0.4073, 0.2123, 108.578],
    [0.0093, 0.503, 0.1582, 107.802],
    [0.0291, 0.6082, 0.1117, 106.296],
    [0.06327, 0.71, 0.07824999, 104.79],
    [0.1096, 0.7932, 0.05725001, 106.239],
    [0.1655, 0.862, 0.04216, 107.689],
    [0.2257499, 0.9148501, 0.02984, 106.047],
    [0.2904, 0.954, 0.0203, 104.405],
    [0.3597, 0.9803, 0.0134, 104.225],
    [0.4334499, 0.9949501, 0.008749999, 104.046],
    [0.5120501, 1.0, 0.005749999, 102.023],
    [0.5945, 0.995, 0.0039, 100.0],
    [0.6784, 0.9786, 0.002749999, 98.1671],
    [0.7621, 0.952, 0.0021, 96.3342],
    [0.8425, 0.9154, 0.0018, 96.0611],
    [0.9163, 0.87, 0.001650001, 95.788],
    [0.9786, 0.8163, 0.0014, 92.2368],
    [1.0263, 0.757, 0.0011, 88.6856],
    [1.0567, 0.6949, 0.001, 89.3459],
    [1.0622, 0.631, 0.0008, 90.0062],
    [1.0456, 0.5668, 0.0006, 89.8026],
    [1.0026, 0.503, 0.00034, 89.5991],
    [0.9384, 0.4412, 0.00024, 88.6489],
    [0.8544499, 0.381, 0.00019, 87.6987],
    [0.7514, 0.321, 0.0001, 85.4936],
    [0.6424, 0.265, 4.999999e-05, 83.2886],
    [0.5419, 0.217, 3e-05, 83.4939],
    [0.4479, 0.175, 2e-05, 83.6992],
    [0.3608, 0.1382, 1e-05, 81.863],
    [0.2835, 0.107, 0.0, 80.0268],
    [0.2187, 0.0816, 0.0, 80.1207],
    [0.1649, 0.061, 0.0, 80.2146],
    [0.1212, 0.04458, 0.0, 81.2462],
    [0.0874, 0.032, 0.0, 82.2778],
    [0.0636, 0.0232, 0.0, 80.281],
    [0.04677, 0.017, 0.0, 78.2842],
    [0.0329, 0.01192, 0.0, 74.0027],
    [0.0227, 0.00821, 0.0, 69.7213],
    [0.01584, 0.005723, 0.0, 70.6652],
    [0.01135916, 0.004102, 0.0, 71.6091],
    [0.008110916, 0.002929, 0.0, 72.979],
    [0.005790346, 0.002091, 0.0, 74.349],
    [0.004109457, 0.001484, 0.0, 67.9765],
    [0.002899327, 0.001047, 0.0, 61.604],
    [0.00204919, 0.00074, 0.0, 65.7448],
    [0.001439971, 0.00052, 0.0, 69.8856],
    [0.0009999493, 0.0003611, 0.0, 72.4863],
    [0.0006900786, 0.0002492, 0.0, 75.087],
    [0.0004760213, 0.0001719, 0.0, 69.3398],
    [0.0003323011, 0.00012, 0.0, 63.5927],
    [0.0002348261, 8.48e-05, 0.0, 55.0054],
    [0.0001661505, 6e-05, 0.0, 46.4182],
    [0.000117413, 4.24e-05, 0.0, 56.6118],
    [8.307527e-05, 3e-05, 0.0, 66.8054],
    [5.870652e-05, 2.12e-05, 0.0, 65.0941],
    [4.150994e-05, 1.499e-05, 0.0, 63.3828],
];

/// The first wavelength of [`CIE_5NM`], nm.
const FIRST_NM: f64 = 360.0;
/// The spacing of [`CIE_5NM`], nm.
const STEP_NM: f64 = 5.0;

/// XYZ (D65 white) to linear Rec.709.
const XYZ_TO_REC709: [[f64; 3]; 3] = [
    [3.240_454_2, -1.537_138_5, -0.498_531_4],
    [-0.969_266_0, 1.876_010_8, 0.041_556_0],
    [0.055_643_4, -0.204_025_9, 1.057_225_2],
];

/// The linear map from spectra sampled at given wavelengths to Rec.709 RGB.
#[derive(Clone, Debug)]
pub struct SpectrumToRgb {
    /// `weights[c][k]`: the contribution of the sample at wavelength k to channel c.
    weights: [Vec<f64>; 3],
}

impl SpectrumToRgb {
    /// The map for samples at `wavelengths` (nm, strictly increasing, finite). An error when
    /// they are not, or when none lies near the visible range.
    pub fn new(wavelengths: &[f64]) -> Result<Self, String> {
        let n = wavelengths.len();
        if n == 0 {
            return Err("no wavelength".into());
        }
        if wavelengths.iter().any(|l| !l.is_finite())
            || wavelengths.windows(2).any(|w| w[0] >= w[1])
        {
            return Err("the wavelengths do not increase".into());
        }
        if wavelengths[n - 1] < FIRST_NM - 50.0 || wavelengths[0] > 780.0 + 50.0 {
            return Err(format!(
                "the wavelengths ({} to {} nm) miss the visible range",
                wavelengths[0],
                wavelengths[n - 1]
            ));
        }
        let mut xyz = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut white_y = 0.0;
        for (j, row) in CIE_5NM.iter().enumerate() {
            let lambda = FIRST_NM + STEP_NM * j as f64;
            let t = if j == 0 || j == CIE_5NM.len() - 1 {
                0.5
            } else {
                1.0
            };
            let [x, y, z, d65] = *row;
            white_y += t * y * d65;
            // S(λ) as the linear interpolant of the samples, constant beyond the ends.
            let k = crate::sources::rgl::warp2d::find_interval(n, |k| wavelengths[k] <= lambda);
            let (k0, k1, f) = if n == 1 {
                (0, 0, 0.0)
            } else {
                let f = (lambda - wavelengths[k]) / (wavelengths[k + 1] - wavelengths[k]);
                (k, k + 1, f.clamp(0.0, 1.0))
            };
            for (c, v) in [x, y, z].into_iter().enumerate() {
                xyz[c][k0] += t * v * d65 * (1.0 - f);
                xyz[c][k1] += t * v * d65 * f;
            }
        }
        let weights = std::array::from_fn(|c| {
            (0..n)
                .map(|k| (0..3).map(|i| XYZ_TO_REC709[c][i] * xyz[i][k]).sum::<f64>() / white_y)
                .collect()
        });
        Ok(SpectrumToRgb { weights })
    }

    /// Number of wavelengths the map takes.
    pub fn len(&self) -> usize {
        self.weights[0].len()
    }

    /// Whether the map takes no wavelength (never, once built).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The RGB of one spectrum (`spectrum[k]` at wavelength k); the samples may be strided
    /// (`spectrum(k)` returns sample k).
    pub fn rgb(&self, spectrum: impl Fn(usize) -> f64) -> [f64; 3] {
        let s: Vec<f64> = (0..self.len()).map(spectrum).collect();
        std::array::from_fn(|c| self.weights[c].iter().zip(&s).map(|(w, v)| w * v).sum())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_white_spectrum_is_white_at_any_sampling() {
        for wavelengths in [
            (0..95).map(|i| 360.0 + 5.0 * i as f64).collect::<Vec<_>>(),
            (0..33).map(|i| 380.0 + 10.0 * i as f64).collect(),
            vec![550.0],
            (0..195).map(|i| 360.0 + 3.3 * i as f64).collect(),
        ] {
            let m = SpectrumToRgb::new(&wavelengths).unwrap();
            let rgb = m.rgb(|_| 1.0);
            for c in rgb {
                assert!(
                    (c - 1.0).abs() < 2e-3,
                    "{rgb:?} at {} wavelengths",
                    wavelengths.len()
                );
            }
        }
    }

    #[test]
    fn a_smooth_spectrum_converts_alike_coarse_and_fine() {
        // A reddish reflectance: the same curve sampled every 1 nm and every 20 nm.
        let s = |l: f64| 0.1 + 0.8 / (1.0 + (-(l - 590.0) / 25.0).exp());
        let fine: Vec<f64> = (0..=420).map(|i| 360.0 + i as f64).collect();
        let coarse: Vec<f64> = (0..=21).map(|i| 360.0 + 20.0 * i as f64).collect();
        let a = SpectrumToRgb::new(&fine).unwrap().rgb(|k| s(fine[k]));
        let b = SpectrumToRgb::new(&coarse).unwrap().rgb(|k| s(coarse[k]));
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() < 3e-3, "{a:?} against {b:?}");
        }
        // Red above green above blue, as the curve rises towards long wavelengths.
        assert!(
            a[0] > 0.6 && a[0] > a[1] && a[1] > a[2] && a[2] > 0.0,
            "{a:?}"
        );
    }

    #[test]
    fn bad_wavelengths_are_named() {
        assert!(SpectrumToRgb::new(&[]).is_err());
        assert!(
            SpectrumToRgb::new(&[500.0, 500.0])
                .unwrap_err()
                .contains("increase")
        );
        assert!(
            SpectrumToRgb::new(&[1200.0, 1300.0])
                .unwrap_err()
                .contains("visible")
        );
    }
}
