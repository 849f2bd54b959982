//! `facet bench`'s shard section: what a shard costs besides its work. A render shard is a
//! `facet render` process of the demo scene (its sky and three fitted spheres, glints included)
//! at the demo's size; it pays the process start, the scene's load, the BVH, the pipelines and
//! the outputs' writing once, whatever its samples. Timed here as that process (this binary),
//! its wall time against the render time it prints, for a few shard sizes; and a fit shard of one
//! embedded proxy, its wall time against the fit's own total. The caller names the binary.

use crate::Assets;
use crate::error::{BenchError, Result};
use crate::timing::median;
use serde_json::{Value, json};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// The demo's size (`facet demo`'s default).
const DEMO_SIZE: (u32, u32) = (480, 270);

/// Share of a shard's wall time that its start-up may take.
const OVERHEAD: f64 = 0.05;

/// The shard section: render shards of each of `spp` samples and a fit shard, `runs` times each
/// (medians), at `size`, as processes of the `facet` binary at `facet`; files go to a temporary
/// folder, removed after.
pub fn shards(
    facet: &Path,
    assets: &Assets,
    runs: usize,
    size: Option<(u32, u32)>,
    spp: &[u32],
) -> Result<Value> {
    let (w, h) = size.unwrap_or(DEMO_SIZE);
    let tmp = std::env::temp_dir().join(format!("facet-bench-shard-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).map_err(BenchError::io(tmp.display().to_string()))?;
    let shards = Shards {
        facet,
        assets,
        tmp: &tmp,
    };
    let result = shards.measure(runs.max(1), (w, h), spp);
    std::fs::remove_dir_all(&tmp).ok();
    result
}

/// The binary, the demo's files and the folder the shards write to.
struct Shards<'a> {
    facet: &'a Path,
    assets: &'a Assets,
    tmp: &'a Path,
}

impl Shards<'_> {
    fn measure(&self, runs: usize, (w, h): (u32, u32), spp: &[u32]) -> Result<Value> {
        println!(
            "\n== shard start-up: the demo at {w}×{h} per shard process, {runs} runs (medians)"
        );
        let mut rows = Vec::new();
        for &s in spp {
            let mut t: Vec<(f64, f64)> = (0..runs)
                .map(|_| self.render_shard(w, h, s))
                .collect::<Result<_>>()?;
            let wall = median(&mut t.iter().map(|r| r.0).collect::<Vec<_>>());
            let render = median(&mut t.iter().map(|r| r.1).collect::<Vec<_>>());
            let startup = median(&mut t.iter_mut().map(|r| r.0 - r.1).collect::<Vec<_>>());
            println!(
                "  {s:>5} spp: wall {wall:8.0} ms, render {render:8.0} ms, start-up {startup:5.0} ms ({:.1} %)",
                100.0 * startup / wall
            );
            rows.push(
                json!({"spp": s, "wall_ms": wall, "render_ms": render, "startup_ms": startup}),
            );
        }
        let startup = median(
            &mut rows
                .iter()
                .map(|r| r["startup_ms"].as_f64().unwrap_or(0.0))
                .collect::<Vec<_>>(),
        );
        // The largest shard's render time per sample: the one least disturbed by the start.
        let last = rows
            .last()
            .ok_or_else(|| BenchError::Other("no shard size".into()))?;
        let per_spp =
            last["render_ms"].as_f64().unwrap_or(0.0) / last["spp"].as_f64().unwrap_or(1.0);
        // startup / (startup + S · per_spp) < OVERHEAD ⇔ S > startup (1 − OVERHEAD) / (OVERHEAD · per_spp)
        let spp_for = startup * (1.0 - OVERHEAD) / (OVERHEAD * per_spp);
        println!(
            "  start-up {startup:.0} ms, {per_spp:.1} ms a sample per pixel: under {:.0} % from {spp_for:.0} spp a shard",
            100.0 * OVERHEAD
        );
        let (fit_wall, fit_ms) = self.fit_shard(runs)?;
        println!(
            "  fit shard of one proxy: wall {fit_wall:.0} ms, the fit {fit_ms:.0} ms, start-up {:.0} ms",
            fit_wall - fit_ms
        );
        Ok(json!({
            "size": [w, h], "runs": runs, "shards": rows, "startup_ms": startup,
            "render_ms_per_spp": per_spp, "spp_for_5_percent": spp_for,
            "fit": {"input": "nbrdf:gold-metallic-paint", "wall_ms": fit_wall, "fit_ms": fit_ms,
                    "startup_ms": fit_wall - fit_ms},
        }))
    }

    /// The binary run with `args` in the folder: its stdout and wall time (ms), or its error.
    fn facet(&self, args: &[String]) -> Result<(String, f64)> {
        let t = Instant::now();
        let out = Command::new(self.facet)
            .args(args)
            .current_dir(self.tmp)
            .output()
            .map_err(BenchError::io(format!("running {}", self.facet.display())))?;
        let wall = t.elapsed().as_secs_f64() * 1e3;
        if !out.status.success() {
            return Err(BenchError::Other(format!(
                "facet {args:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            )));
        }
        Ok((String::from_utf8_lossy(&out.stdout).into_owned(), wall))
    }

    /// One render shard of `s` samples: (wall ms, render ms as it prints it).
    fn render_shard(&self, w: u32, h: u32, s: u32) -> Result<(f64, f64)> {
        let (gltf, sky, fit) = (
            self.assets.demo_gltf(),
            self.assets.sky(),
            self.assets.demo_fit(),
        );
        let mut args: Vec<String> = ["render", &gltf.display().to_string(), "--env"]
            .iter()
            .map(|a| a.to_string())
            .collect();
        args.push(sky.display().to_string());
        for m in ["tabulated", "ggx", "glint"] {
            args.extend(["--material".into(), format!("{m}={}", fit.display())]);
        }
        args.extend([
            "--width".into(),
            w.to_string(),
            "--height".into(),
            h.to_string(),
            "--samples".into(),
            format!("0..{s}"),
            "--out".into(),
            "shard.png".into(),
        ]);
        let (stdout, wall) = self.facet(&args)?;
        let render = stdout
            .lines()
            .find_map(|l| {
                l.split_once(", render ")
                    .and_then(|(_, r)| r.split_once(' '))
            })
            .and_then(|(ms, _)| ms.parse::<f64>().ok())
            .ok_or_else(|| BenchError::Other(format!("no render time in {stdout}")))?;
        Ok((wall, render))
    }

    /// A fit shard of one embedded proxy, `runs` times: median (wall ms, the fit's total ms).
    fn fit_shard(&self, runs: usize) -> Result<(f64, f64)> {
        let mut t = Vec::new();
        for k in 0..runs {
            let out = format!("fit{k}");
            let args = ["fit", "nbrdf:gold-metallic-paint", "--out", &out].map(String::from);
            let (_, wall) = self.facet(&args)?;
            let json = self.tmp.join(&out).join("gold-metallic-paint.json");
            let text = std::fs::read_to_string(&json)
                .map_err(BenchError::io(json.display().to_string()))?;
            let record: Value = serde_json::from_str(&text)?;
            let total = record["timings_ms"]["total"]
                .as_f64()
                .ok_or_else(|| BenchError::Other("no timings_ms.total in the fit record".into()))?;
            t.push((wall, total));
        }
        let wall = median(&mut t.iter().map(|r| r.0).collect::<Vec<_>>());
        let fit = median(&mut t.iter().map(|r| r.1).collect::<Vec<_>>());
        Ok((wall, fit))
    }
}
