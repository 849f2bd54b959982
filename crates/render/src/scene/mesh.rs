//! One glTF primitive made renderable: bad triangles dropped, vertices compacted, normals and
//! tangents generated where the file has none, every attribute finite.
//!
//! Everything here works on world-space arrays (the loader transforms first), so generated
//! normals and tangents are those of the surface as it is rendered.

use glam::{Vec2, Vec3, Vec4};

/// A primitive's attributes in world space, as read from the file.
#[derive(Clone, Debug, Default)]
pub struct RawPrimitive {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Normals, if the file has them.
    pub normals: Option<Vec<Vec3>>,
    /// Texture coordinates, if the file has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Tangents, if the file has them.
    pub tangents: Option<Vec<Vec4>>,
    /// Indices already checked to be `< positions.len()`.
    pub indices: Vec<[u32; 3]>,
}

/// A primitive with every attribute present, finite and unit where it should be.
#[derive(Clone, Debug, Default)]
pub struct CleanPrimitive {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Unit normals.
    pub normals: Vec<Vec3>,
    /// Texture coordinates.
    pub uvs: Vec<Vec2>,
    /// Tangents, xyz unit and w = ±1.
    pub tangents: Vec<Vec4>,
    /// Triangles as vertex indices.
    pub indices: Vec<[u32; 3]>,
    /// Triangles dropped for zero area or a non-finite corner.
    pub dropped: usize,
}

/// Twice the triangle's area as a vector: `(p1 − p0) × (p2 − p0)`.
fn area_vector(p: &[Vec3], t: [u32; 3]) -> Vec3 {
    let [a, b, c] = t.map(|i| p[i as usize]);
    (b - a).cross(c - a)
}

/// Drops degenerate triangles, compacts the vertices they leave unused and fills every attribute.
pub fn clean_primitive(raw: RawPrimitive) -> CleanPrimitive {
    let p = &raw.positions;
    // A triangle survives when its corners are finite and its area is not zero.
    let keep: Vec<[u32; 3]> = raw
        .indices
        .iter()
        .copied()
        .filter(|&t| {
            t.iter().all(|&i| p[i as usize].is_finite()) && {
                let a = area_vector(p, t).length_squared();
                a.is_finite() && a > 0.0
            }
        })
        .collect();
    let dropped = raw.indices.len() - keep.len();

    // Compact: old vertex index → new, in order of first use.
    let mut remap = vec![u32::MAX; p.len()];
    let mut order = Vec::new();
    let indices: Vec<[u32; 3]> = keep
        .iter()
        .map(|t| {
            t.map(|i| {
                let slot = &mut remap[i as usize];
                if *slot == u32::MAX {
                    *slot = order.len() as u32;
                    order.push(i as usize);
                }
                *slot
            })
        })
        .collect();
    let pick = |v: &[Vec3]| order.iter().map(|&i| v[i]).collect::<Vec<_>>();
    let positions = pick(p);

    let generated = generate_normals(&positions, &indices);
    let normals = match &raw.normals {
        // A given normal that is not finite or not normalisable falls back to the generated one.
        Some(n) => order
            .iter()
            .zip(&generated)
            .map(|(&i, &g)| n[i].try_normalize().unwrap_or(g))
            .collect(),
        None => generated,
    };
    let uvs: Vec<Vec2> = match &raw.uvs {
        Some(uv) => order
            .iter()
            .map(|&i| if uv[i].is_finite() { uv[i] } else { Vec2::ZERO })
            .collect(),
        None => vec![Vec2::ZERO; positions.len()],
    };
    let generated_t = generate_tangents(&positions, &normals, &uvs, &indices);
    let tangents = match &raw.tangents {
        Some(t) => order
            .iter()
            .zip(normals.iter().zip(&generated_t))
            .map(|(&i, (&n, &g))| {
                let t = t[i];
                // Keep the file's tangent, made orthogonal to the normal (Gram–Schmidt).
                match (t.truncate() - n * n.dot(t.truncate())).try_normalize() {
                    Some(xyz) if t.w.is_finite() => xyz.extend(if t.w < 0.0 { -1.0 } else { 1.0 }),
                    _ => g,
                }
            })
            .collect(),
        None => generated_t,
    };
    CleanPrimitive {
        positions,
        normals,
        uvs,
        tangents,
        indices,
        dropped,
    }
}

/// Area-weighted vertex normals: `n_v = normalize(Σ_t∋v (p1 − p0) × (p2 − p0))` (the cross
/// product's length is twice the area). A vertex whose sum vanishes gets +Y.
pub fn generate_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sum = vec![Vec3::ZERO; positions.len()];
    for &t in indices {
        let n = area_vector(positions, t);
        for i in t {
            sum[i as usize] += n;
        }
    }
    sum.into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
        .collect()
}

/// Per-vertex tangents from UVs, glTF convention (xyz unit ⟂ n, w = ±1 with
/// bitangent = w · (n × t)).
///
/// Per triangle with edges `e1 = p1 − p0`, `e2 = p2 − p0` and UV edges `(du1, dv1)`,
/// `(du2, dv2)`, `r = du1 dv2 − du2 dv1`:
/// `dP/du = (e1 dv2 − e2 dv1) / r`, `dP/dv = (e2 du1 − e1 du2) / r`, summed over the triangles
/// of each vertex; then `t = normalize(dP/du − n (n·dP/du))` (Gram–Schmidt) and
/// `w = sign((n × t) · dP/dv)`. Where UVs are degenerate, any unit tangent ⟂ n with w = 1.
pub fn generate_tangents(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    indices: &[[u32; 3]],
) -> Vec<Vec4> {
    let mut dpdu = vec![Vec3::ZERO; positions.len()];
    let mut dpdv = vec![Vec3::ZERO; positions.len()];
    for &t in indices {
        let [i0, i1, i2] = t.map(|i| i as usize);
        let (e1, e2) = (positions[i1] - positions[i0], positions[i2] - positions[i0]);
        let (d1, d2) = (uvs[i1] - uvs[i0], uvs[i2] - uvs[i0]);
        let r = d1.x * d2.y - d2.x * d1.y;
        if !(r.abs() > 1e-20) {
            continue;
        }
        let tu = (e1 * d2.y - e2 * d1.y) / r;
        let tv = (e2 * d1.x - e1 * d2.x) / r;
        if !(tu.is_finite() && tv.is_finite()) {
            continue;
        }
        for i in [i0, i1, i2] {
            dpdu[i] += tu;
            dpdv[i] += tv;
        }
    }
    normals
        .iter()
        .zip(dpdu.iter().zip(&dpdv))
        .map(
            |(&n, (&tu, &tv))| match (tu - n * n.dot(tu)).try_normalize() {
                Some(t) => {
                    let w = if n.cross(t).dot(tv) < 0.0 { -1.0 } else { 1.0 };
                    t.extend(w)
                }
                None => n.any_orthonormal_vector().extend(1.0),
            },
        )
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_in_xz_gets_up_normal_and_u_tangent() {
        // Counter-clockwise seen from +Y.
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let uvs = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
        ];
        let indices = vec![[0, 1, 2], [0, 2, 3]];
        let n = generate_normals(&positions, &indices);
        assert!(n.iter().all(|n| (*n - Vec3::Y).length() < 1e-6), "{n:?}");
        let t = generate_tangents(&positions, &n, &uvs, &indices);
        for t in &t {
            assert!((t.truncate() - Vec3::X).length() < 1e-6, "{t:?}");
            // n × t = Y × X = −Z, and dP/dv = +Z: w = −1.
            assert_eq!(t.w, -1.0);
        }
    }

    #[test]
    fn degenerate_uvs_give_orthonormal_tangents() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let n = vec![Vec3::Z; 3];
        let t = generate_tangents(&positions, &n, &[Vec2::ZERO; 3], &[[0, 1, 2]]);
        for t in t {
            assert!(
                (t.truncate().length() - 1.0).abs() < 1e-6
                    && t.truncate().dot(Vec3::Z).abs() < 1e-6
            );
        }
    }
}
