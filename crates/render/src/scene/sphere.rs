//! The sphere under a light: a unit sphere at the origin, on a floor or alone, seen by one
//! camera, lit by a point light or by the environment alone. One builder and its presets for
//! every caller: the viewer's preview ([`SphereScene::PREVIEW`]), `facet bench`'s gold scene
//! ([`SphereScene::GOLD`]), `facet report`'s spheres ([`SphereScene::REPORT`]) and the render
//! tests ([`SphereScene::TEST`], [`SphereScene::SMALL`]). Each preset reproduces its caller's
//! scene exactly (tessellation, floor, camera, light): the report's ΔE figures and the tests'
//! references depend on them.
//!
//! ```
//! use facet_render::scene::Material;
//! use facet_render::scene::sphere::SphereScene;
//!
//! let scene = SphereScene::GOLD.build(Material::default());
//! assert_eq!(scene.materials.len(), 2); // the floor (0), then the sphere (1)
//! assert_eq!(scene.lights.len(), 1);
//! let alone = SphereScene::REPORT.without_light().build(Material::default());
//! assert!(alone.lights.is_empty());
//! ```

use super::{Camera, Light, Material, Scene};
use glam::{Vec3, Vec4};

/// A unit sphere at the origin and what surrounds it: plain data, built by
/// [`SphereScene::build`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereScene {
    /// The UV sphere's segments around +Y.
    pub segments: u32,
    /// Its rings from pole to pole.
    pub rings: u32,
    /// A grey square floor under the sphere (material 0, the sphere then material 1), or none
    /// (the sphere material 0).
    pub floor: Option<Floor>,
    /// Where the camera stands and looks.
    pub view: View,
    /// The camera's vertical field of view, degrees.
    pub yfov_deg: f32,
    /// One point light, or none.
    pub light: Option<PointLight>,
}

/// A square floor at y = −1 (touching the sphere), centred under it, Lambertian or glTF
/// metallic-roughness grey.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Floor {
    /// Half its side.
    pub half_size: f32,
    /// The UV scale over the whole square.
    pub uv_scale: f32,
    /// The grey base colour.
    pub albedo: f32,
    /// glTF roughness.
    pub roughness: f32,
    /// glTF metallic.
    pub metallic: f32,
    /// glTF specular weight (0: a Lambertian floor).
    pub specular: f32,
}

/// The camera's placement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// At `position`, looking along `toward` (normalised when built), +Y up.
    Look {
        /// The camera's position.
        position: Vec3,
        /// The direction it looks in, any length.
        toward: Vec3,
    },
    /// At `distance` from the sphere's centre, `pitch` radians above the horizon on the +z
    /// side, looking at the centre, up the component of +Y across the view.
    Orbit {
        /// The distance from the centre.
        distance: f32,
        /// The elevation, radians.
        pitch: f32,
    },
}

/// A point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Its position.
    pub position: Vec3,
    /// Its radiant intensity, the same in every channel.
    pub intensity: f32,
}

impl SphereScene {
    /// The viewer's preview (`facet-viewer`; `facet bench`'s viewer row and glossy sphere): a
    /// 96 × 48 sphere on a 16 × 16 glTF grey floor, seen from 4.5 away, 0.25 rad above the
    /// horizon; no light (the environment lights it).
    pub const PREVIEW: SphereScene = SphereScene {
        segments: 96,
        rings: 48,
        floor: Some(Floor {
            half_size: 8.0,
            uv_scale: 4.0,
            albedo: 0.45,
            roughness: 0.8,
            metallic: 0.0,
            specular: 1.0,
        }),
        view: View::Orbit {
            distance: 4.5,
            pitch: 0.25,
        },
        yfov_deg: 35.0,
        light: None,
    };

    /// Issue 12's gold scene (`facet bench`'s noise, light, measured and coat sections): a
    /// 128 × 64 sphere on a 20 × 20 grey Lambertian floor, a 40 W/sr point light; the bench
    /// adds a constant sky of 0.5.
    pub const GOLD: SphereScene = SphereScene {
        segments: 128,
        rings: 64,
        floor: Some(Floor {
            half_size: 10.0,
            uv_scale: 1.0,
            albedo: 0.5,
            roughness: 1.0,
            metallic: 0.0,
            specular: 0.0,
        }),
        view: View::Look {
            position: Vec3::new(0.0, 1.5, 5.0),
            toward: Vec3::new(0.0, -1.5, -5.0),
        },
        yfov_deg: 40.0,
        light: Some(PointLight {
            position: Vec3::new(2.0, 3.0, 2.0),
            intensity: 40.0,
        }),
    };

    /// `facet report`'s spheres (facet-fit's `metric::look::SphereScene::REPORT`, the scene a
    /// fit's look is judged in): a 192 × 96 sphere alone, the camera on +z at 3 with a 45°
    /// field of view, the point light upper left in front at distance ≈ 3.9, of intensity 40
    /// (a white Lambertian facing it gives L = I/(π r²) ≈ 1.5); without it
    /// ([`SphereScene::without_light`]) for the environment renders.
    pub const REPORT: SphereScene = SphereScene {
        segments: 192,
        rings: 96,
        floor: None,
        view: View::Look {
            position: Vec3::new(0.0, 0.0, 3.0),
            toward: Vec3::NEG_Z,
        },
        yfov_deg: 45.0,
        light: Some(PointLight {
            position: Vec3::new(-1.6, 1.8, 3.0),
            intensity: 40.0,
        }),
    };

    /// The GPU render tests' sphere (facet-render's `analytic_scenes`, `integrator`): a
    /// 256 × 128 sphere alone filling most of the frame, seen from +z at 3 with a 36° field of
    /// view; no light (each test adds its own).
    pub const TEST: SphereScene = SphereScene {
        segments: 256,
        rings: 128,
        floor: None,
        view: View::Look {
            position: Vec3::new(0.0, 0.0, 3.0),
            toward: Vec3::NEG_Z,
        },
        yfov_deg: 36.0,
        light: None,
    };

    /// A coarse 32 × 16 sphere alone seen from +z at 3.5 with a 45° field of view (tests that
    /// compare two renders of it, as `update_material`).
    pub const SMALL: SphereScene = SphereScene {
        segments: 32,
        rings: 16,
        view: View::Look {
            position: Vec3::new(0.0, 0.0, 3.5),
            toward: Vec3::NEG_Z,
        },
        yfov_deg: 45.0,
        ..SphereScene::TEST
    };

    /// Every preset, for tests that check them all.
    pub const ALL: [SphereScene; 5] = [
        SphereScene::PREVIEW,
        SphereScene::GOLD,
        SphereScene::REPORT,
        SphereScene::TEST,
        SphereScene::SMALL,
    ];

    /// The same scene without its point light.
    pub const fn without_light(self) -> SphereScene {
        SphereScene {
            light: None,
            ..self
        }
    }

    /// The index of the sphere's material in the built scene.
    pub const fn sphere_material(&self) -> u32 {
        if self.floor.is_some() { 1 } else { 0 }
    }

    /// The scene: the floor's material and quad first where there is one, then `sphere` and
    /// its mesh, the camera and the light.
    pub fn build(&self, sphere: Material) -> Scene {
        let mut scene = Scene::default();
        if let Some(floor) = &self.floor {
            scene.materials.push(floor.material());
            let h = floor.half_size;
            scene.add_quad(
                Vec3::new(-h, -1.0, h),
                Vec3::new(2.0 * h, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -2.0 * h),
                floor.uv_scale,
                0,
            );
        }
        scene.materials.push(sphere);
        let m = self.sphere_material();
        scene.add_uv_sphere(Vec3::ZERO, 1.0, self.segments, self.rings, m);
        scene.camera = self.camera();
        if let Some(light) = &self.light {
            scene.lights.push(Light::Point {
                position: light.position,
                intensity: Vec3::splat(light.intensity),
            });
        }
        scene
    }

    /// The camera of [`SphereScene::view`].
    pub fn camera(&self) -> Camera {
        let yfov = self.yfov_deg.to_radians();
        match self.view {
            View::Look { position, toward } => Camera {
                position,
                forward: toward.normalize(),
                up: Vec3::Y,
                yfov,
            },
            View::Orbit { distance, pitch } => {
                let position = Vec3::new(0.0, pitch.sin(), pitch.cos()) * distance;
                let forward = -position.normalize();
                Camera {
                    position,
                    forward,
                    up: (Vec3::Y - forward * forward.dot(Vec3::Y)).normalize(),
                    yfov,
                }
            }
        }
    }
}

impl Floor {
    /// The floor's material, named `floor`.
    fn material(&self) -> Material {
        Material {
            name: "floor".into(),
            base_color: Vec4::new(self.albedo, self.albedo, self.albedo, 1.0),
            roughness: self.roughness,
            metallic: self.metallic,
            specular: self.specular,
            ..Material::default()
        }
    }
}
