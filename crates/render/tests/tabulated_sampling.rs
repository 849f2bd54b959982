//! The tabulated NDF's visible-normal sampling in WGSL (shaders/render/materials/tabulated.inc.wgsl): its
//! histogram against the CPU twin's pdf (χ²) and its pdf against the CPU's, for the demo fit's
//! extracted table (plain, and stretched and rotated) and an anisotropic table, from normal to
//! grazing views.

mod common;

use facet_fit::model::geometry::spherical;
use facet_fit::model::material::FittedMaterial;
use facet_fit::model::microfacet::Ndf;
use facet_fit::model::microfacet::{AnalyticNdf, NdfKind};
use facet_fit::model::tabulated::{NdfTables, Stretch, TabulatedNdf, phi_node, u_node_theta};
use facet_fit::numerics::chi2;
use facet_gpu::{buffer, shader};
use facet_render::materials::tabulated::tabulated_block;
use glam::DVec3;
use std::path::Path;

fn demo_table() -> TabulatedNdf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/demo/default_fit.json");
    let fit = FittedMaterial::load(&p).unwrap();
    let Ndf::Tabulated(t) = &fit.tabulated.ndf else {
        panic!("the demo fit has a tabulated NDF");
    };
    (**t).clone()
}

fn anisotropic_table() -> TabulatedNdf {
    let d = AnalyticNdf {
        kind: NdfKind::Beckmann,
        alpha_x: 0.15,
        alpha_y: 0.4,
        rotation: 0.0,
    };
    let (nu, nphi) = (17, 24);
    let mut v = Vec::new();
    for k in 0..nu {
        for l in 0..nphi {
            v.push(d.d(spherical(u_node_theta(k, nu), phi_node(l, nphi))));
        }
    }
    let tables = NdfTables {
        nu,
        nphi,
        d: v,
        ng: 2,
        g1: vec![1.0; 2 * nphi],
    };
    TabulatedNdf::new(tables, Stretch::IDENTITY).unwrap()
}

#[test]
fn gpu_visible_sampling_of_tabulated_ndfs_follows_its_pdf() {
    let Some(gpu) =
        facet_gpu::gpu_for_tests("gpu_visible_sampling_of_tabulated_ndfs_follows_its_pdf")
    else {
        return;
    };
    let stretched = Stretch {
        alpha_x: 0.5,
        alpha_y: 1.7,
        rotation: 0.6,
    };
    let cases = [
        ("demo fit", demo_table()),
        ("demo fit stretched", demo_table().with_stretch(stretched)),
        ("anisotropic", anisotropic_table()),
        (
            "anisotropic rotated",
            anisotropic_table().with_stretch(stretched),
        ),
    ];
    let pipeline = shader::compute_pipeline(
        &gpu.device,
        "tests/render/tabulated_sample.wgsl",
        "tabulated_sample",
        &[],
    )
    .unwrap();
    let wg =
        shader::workgroup_size("tests/render/tabulated_sample.wgsl", "tabulated_sample").unwrap();
    let n = 200_000u32;
    for (what, ndf) in &cases {
        let s = ndf.stretch;
        let params = [s.alpha_x as f32, s.alpha_y as f32, s.rotation as f32, 0.0];
        let tb = buffer::storage(&gpu.device, "tables", &tabulated_block(ndf));
        let ub = buffer::uniform(&gpu.device, "stretch", &params);
        for theta_deg in [0.0f64, 33.0, 61.0, 85.0] {
            let t = theta_deg.to_radians();
            let wo = DVec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos()).as_vec3();
            let mut next = chi2::uniforms(theta_deg as u64 + 17);
            let inputs: Vec<[f32; 4]> = (0..n)
                .flat_map(|_| {
                    let u = [next() as f32, next() as f32];
                    [[wo.x, wo.y, wo.z, u[0]], [u[1], 0.0, 0.0, 0.0]]
                })
                .collect();
            let ib = buffer::storage(&gpu.device, "inputs", &inputs);
            let out = common::probe(
                &gpu,
                &pipeline,
                "tabulated sample",
                &[
                    tb.as_entire_binding(),
                    ub.as_entire_binding(),
                    ib.as_entire_binding(),
                ],
                n,
                wg,
            );
            let wo = wo.as_dvec3();
            let samples: Vec<DVec3> = out
                .iter()
                .map(|g| DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64).normalize())
                .collect();
            // The GPU's pdf of its own normals is the CPU's, but where f32 puts a normal on
            // the other side of a cell edge than f64 does.
            let off = out
                .iter()
                .zip(&samples)
                .filter(|(g, h)| (g[3] as f64 / ndf.pdf_visible(wo, **h) - 1.0).abs() > 2e-3)
                .count();
            let r = chi2::chi2_hemisphere(&samples, |h| ndf.pdf_visible(wo, h), 64);
            println!(
                "{what} θo {theta_deg}°: χ² {:.0} on {} dof, z {:.2}, ∫pdf {:.4}; {off} of {n} GPU pdfs off by > 2e-3",
                r.chi2, r.dof, r.z, r.integral
            );
            assert!(r.z < 5.0, "{what} θo {theta_deg}°: χ² z = {}", r.z);
            // The midpoint rule's error on the narrowest lobe (0.075 × 0.68) is ~1e-3.
            assert!(
                (r.integral - 1.0).abs() < 3e-3,
                "{what}: ∫ pdf {}",
                r.integral
            );
            assert!(off as f64 <= 2e-3 * n as f64, "{what}: {off} pdfs differ");
        }
    }
}
