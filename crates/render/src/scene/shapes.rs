//! Scenes built in code: meshes appended to a [`Scene`] (tests, benchmarks, generated scenes;
//! the sphere scenes of [`super::sphere`]).

use super::Scene;
use glam::{Vec2, Vec3, Vec4};

impl Scene {
    /// Appends an indexed mesh (all vectors already in world space) with one material.
    pub fn add_mesh(
        &mut self,
        positions: &[Vec3],
        normals: &[Vec3],
        uvs: &[Vec2],
        tangents: &[Vec4],
        indices: &[[u32; 3]],
        material: u32,
    ) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(positions);
        self.normals.extend_from_slice(normals);
        self.uvs.extend_from_slice(uvs);
        self.tangents.extend_from_slice(tangents);
        self.indices
            .extend(indices.iter().map(|t| t.map(|i| i + base)));
        self.triangle_material
            .extend(std::iter::repeat_n(material, indices.len()));
    }

    /// Appends bare triangles: area-weighted vertex normals, zero UVs, generated tangents.
    pub fn add_triangles(&mut self, positions: &[Vec3], indices: &[[u32; 3]], material: u32) {
        let normals = super::mesh::generate_normals(positions, indices);
        let uvs = vec![Vec2::ZERO; positions.len()];
        let tangents = super::mesh::generate_tangents(positions, &normals, &uvs, indices);
        self.add_mesh(positions, &normals, &uvs, &tangents, indices, material);
    }

    /// A UV sphere: u = φ / 2π around +Y, v = θ / π from the top; tangents along +φ.
    pub fn add_uv_sphere(
        &mut self,
        center: Vec3,
        radius: f32,
        segments: u32,
        rings: u32,
        material: u32,
    ) {
        let (mut p, mut n, mut uv, mut t, mut idx) = (vec![], vec![], vec![], vec![], vec![]);
        for r in 0..=rings {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            for s in 0..=segments {
                let phi = std::f32::consts::TAU * s as f32 / segments as f32;
                let d = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                p.push(center + radius * d);
                n.push(d);
                uv.push(Vec2::new(
                    s as f32 / segments as f32,
                    r as f32 / rings as f32,
                ));
                t.push(Vec4::new(-phi.sin(), 0.0, phi.cos(), 1.0));
            }
        }
        let row = segments + 1;
        for r in 0..rings {
            for s in 0..segments {
                let (a, b) = (r * row + s, r * row + s + 1);
                let (c, d) = (a + row, b + row);
                // Counter-clockwise seen from outside; the degenerate pole triangles are skipped.
                if r != 0 {
                    idx.push([a, b, c]);
                }
                if r + 1 != rings {
                    idx.push([b, d, c]);
                }
            }
        }
        self.add_mesh(&p, &n, &uv, &t, &idx, material);
    }

    /// A parallelogram `corner + s·edge_u + t·edge_v`, s, t ∈ [0, 1], UVs (s, t) scaled by
    /// `uv_scale`, facing edge_u × edge_v.
    pub fn add_quad(
        &mut self,
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
        uv_scale: f32,
        material: u32,
    ) {
        let n = edge_u.cross(edge_v).normalize();
        let t = edge_u.normalize().extend(1.0);
        let p = [
            corner,
            corner + edge_u,
            corner + edge_u + edge_v,
            corner + edge_v,
        ];
        let uv = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y].map(|u| u * uv_scale);
        self.add_mesh(&p, &[n; 4], &uv, &[t; 4], &[[0, 1, 2], [0, 2, 3]], material);
    }
}
