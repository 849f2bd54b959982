//! The report's settings: plain data that `facet report`'s arguments convert into.

use facet_fit::FitConfig;
use facet_fit::fitting::CoatSearch;
use facet_fit::model::metric::Metric;

/// What a report renders and fits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReportConfig {
    /// Side of each sphere image, pixels.
    pub side: u32,
    /// Samples per pixel of the environment renders (the point-light renders take
    /// [`POINT_SPP`](crate::scenes::POINT_SPP)).
    pub env_spp: u32,
    /// Polar nodes N of the fits.
    pub fit_resolution: usize,
    /// When the fits search a clear coat (kept where it looks better).
    pub coat: CoatSearch,
    /// The objective the fits minimise.
    pub metric: Metric,
    /// How many of the reported inputs, from the first, the N sweep fits again (0: no sweep).
    pub sweep: usize,
}

impl ReportConfig {
    /// `facet report`'s defaults: 128² spheres, 16 spp, N = 90, the coat searched where it
    /// may help, the perceptual metric, the first two inputs swept.
    pub const DEFAULT: ReportConfig = ReportConfig {
        side: 128,
        env_spp: 16,
        fit_resolution: 90,
        coat: CoatSearch::Auto,
        metric: Metric::Perceptual,
        sweep: 2,
    };

    /// The fits' configuration: isotropic, at [`fit_resolution`](Self::fit_resolution), with
    /// this coat search and metric.
    pub fn fit_config(&self) -> FitConfig {
        let mut cfg = FitConfig {
            coat: self.coat,
            metric: self.metric,
            ..FitConfig::isotropic()
        };
        cfg.extract.resolution = self.fit_resolution;
        cfg
    }

    /// The coat search in words, for the page.
    pub fn coat_words(&self) -> &'static str {
        match self.coat {
            CoatSearch::Auto => {
                "a clear coat searched where the single layer's point-light sphere is above \
                 ΔE2000 0.9, kept where it looks better"
            }
            CoatSearch::Always => {
                "a clear coat searched for every material, kept where it looks better"
            }
            CoatSearch::Off => "no coat searched",
        }
    }
}

impl Default for ReportConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}
