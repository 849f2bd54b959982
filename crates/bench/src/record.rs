//! The JSON record of a benchmark run: its header (mode, commit, date, adapter and the limits
//! requested), to which each section adds its own key.

use facet_gpu::Gpu;
use serde_json::{Value, json};

/// The record's header for `mode` at `commit`, printed as its first lines; the adapter's
/// description and limits where there is one.
pub fn header(mode: &str, commit: &str, gpu: Option<&Gpu>) -> Value {
    let mut report = json!({
        "facet_bench": 1,
        "mode": mode,
        "commit": commit,
        "date": utc_now(),
    });
    println!(
        "facet bench ({mode}), commit {commit}, {}",
        report["date"].as_str().unwrap_or("")
    );
    if let Some(g) = gpu {
        let info = g.adapter.get_info();
        let l = g.device.limits();
        report["adapter"] = json!({
            "name": info.name, "backend": format!("{:?}", info.backend),
            "device_type": format!("{:?}", info.device_type),
            "driver": info.driver, "driver_info": info.driver_info,
            "timestamps": g.device.features().contains(wgpu::Features::TIMESTAMP_QUERY),
        });
        report["limits_requested"] = json!({
            "max_storage_buffer_binding_size": l.max_storage_buffer_binding_size,
            "max_buffer_size": l.max_buffer_size,
            "max_compute_workgroups_per_dimension": l.max_compute_workgroups_per_dimension,
            "max_compute_invocations_per_workgroup": l.max_compute_invocations_per_workgroup,
            "max_texture_dimension_3d": l.max_texture_dimension_3d,
        });
        println!(
            "adapter: {} ({:?}, {:?}), driver {} {}",
            info.name, info.backend, info.device_type, info.driver, info.driver_info
        );
    }
    report
}

/// Now as ISO 8601 UTC (days to civil date: Hinnant's algorithm).
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}
