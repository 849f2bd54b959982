//! The noise and speed of one configuration on one scene: two renders with different seeds give
//! a pixel's variance, E[(a − b)²] / 2, and three the median time a sample; a side-by-side row
//! of the sections that compare materials on the gold scene.

use crate::error::Result;
use crate::scenes::{gold_scene, square};
use crate::timing::median;
use facet_gpu::Gpu;
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{Environment, Material, Scene};
use facet_render::{ImageConfig, Integrator, ResourceConfig, SampleConfig, SceneResources};
use serde_json::{Value, json};

/// `material` on the gold scene's sphere at `side`² and `spp` ([`measure_noise`]), with its
/// time a sample and variance as ratios to the first call's (`first` keeps them): one row of a
/// side-by-side section, as measured, as [time ratio, variance ratio], and as JSON.
pub fn gold_row(
    gpu: &Gpu,
    material: Material,
    side: u32,
    spp: u32,
    first: &mut Option<(f64, f64)>,
) -> Result<(Measured, [f64; 2], Value)> {
    let (scene, env) = gold_scene(material);
    let m = measure_noise(
        gpu,
        &scene,
        Some(&env),
        ResourceConfig::standard(),
        square(side),
        spp,
        facet_render::NdfSampling::Visible,
    )?;
    let (v0, t0) = *first.get_or_insert((m.var, m.ns));
    let ratios = [m.ns / t0, m.var / v0];
    let row = json!({"ns_per_sample": m.ns, "time_ratio": ratios[0], "variance": m.var, "variance_ratio": ratios[1], "mean": m.mean});
    Ok((m, ratios, row))
}

/// One configuration's noise and speed, and the renders they come from.
pub struct Measured {
    /// The variance of a pixel: E[(a − b)²] / 2 over two seeds, averaged over pixels and
    /// channels.
    pub var: f64,
    /// Nanoseconds a sample (median of three renders).
    pub ns: f64,
    /// The mean of both renders' pixels.
    pub mean: f64,
    /// The squared standard error of that mean (pixels independent).
    pub se2: f64,
    /// The two renders (seeds 0 and 1).
    pub images: [facet_render::Image; 2],
}

impl Measured {
    /// The variance of a pixel over the pixels `keep` accepts.
    pub fn variance_where(&self, keep: impl Fn(usize) -> bool) -> f64 {
        let [a, b] = &self.images;
        let (mut sum, mut n) = (0.0, 0usize);
        for (k, (pa, pb)) in a.pixels.iter().zip(&b.pixels).enumerate() {
            if keep(k) {
                sum += (0..3)
                    .map(|c| 0.5 * (pa[c] as f64 - pb[c] as f64).powi(2))
                    .sum::<f64>();
                n += 3;
            }
        }
        sum / n.max(1) as f64
    }
}

/// Renders `scene` at `image` and `spp` (depth 5) with seeds 0, 1 and 2 after an untimed
/// 1-spp render: the variance from the first two, the time a sample the median of the three.
pub fn measure_noise(
    gpu: &Gpu,
    scene: &Scene,
    env: Option<&Environment>,
    rc: ResourceConfig,
    image: ImageConfig,
    spp: u32,
    ndf_sampling: facet_render::NdfSampling,
) -> Result<Measured> {
    let camera = CameraFrame::new(&scene.camera)?;
    let res = SceneResources::new(gpu, scene, env, rc)?;
    let integrator = Integrator::new(&gpu.device, &res)?;
    let mut wf = integrator.wavefront(gpu, &res, image)?;
    let mut images = Vec::new();
    let mut ms = Vec::new();
    // An untimed render first: the first dispatches of fresh pipelines are slower.
    let warm = SampleConfig {
        spp: 1,
        ndf_sampling,
        ..SampleConfig::standard()
    };
    integrator.render_more(gpu, &mut wf, &camera, &warm, &mut |_| {})?;
    // Seeds 0 and 1 give the variance; seed 2 only a third time for the median.
    for seed in [0, 1, 2] {
        let cfg = SampleConfig {
            spp,
            max_depth: 5,
            seed,
            ndf_sampling,
            ..SampleConfig::standard()
        };
        wf.clear(gpu);
        ms.push(
            integrator
                .render_more(gpu, &mut wf, &camera, &cfg, &mut |_| {})?
                .ms,
        );
        if seed < 2 {
            images.push(wf.image(gpu)?);
        }
    }
    let n = images[0].pixels.len() * 3;
    let var = images[0]
        .pixels
        .iter()
        .flatten()
        .zip(images[1].pixels.iter().flatten())
        .map(|(a, b)| 0.5 * (*a as f64 - *b as f64).powi(2))
        .sum::<f64>()
        / n as f64;
    let ns = median(&mut ms) * 1e6 / (image.width as f64 * image.height as f64 * spp as f64);
    let mean = images
        .iter()
        .flat_map(|im| im.pixels.iter().flatten())
        .map(|v| *v as f64)
        .sum::<f64>()
        / (2 * n) as f64;
    let [a, b]: [facet_render::Image; 2] = images.try_into().expect("two renders");
    Ok(Measured {
        var,
        ns,
        mean,
        se2: var / (2 * n) as f64,
        images: [a, b],
    })
}
