//! The current contacts as parallel arrays, for output and analysis.
use crate::contact::contact_point;
use crate::error::Result;
use crate::pipeline::Simulation;
use crate::vec2::{scale, Vec2};

/// One row of the contact table while it is assembled.
type ContactRow = (u32, u32, Vec2, Vec2, f64, f64, f64, bool, bool, f64, f64);

/// Particle-particle contacts and bonds, sorted by `(i, j)` with `i < j`,
/// in external (user) particle indices.
///
/// Every row is one consistent state, the forces at the current positions
/// exactly as the next force evaluation will compute them: the normal force
/// from the current overlap, the shear spring with the increment of the
/// displacement made since the last evaluation (none when velocities were just
/// set), capped at `mu * normal_force`. `normal` points from `i` to `j`;
/// `normal_force` (N, `kn * overlap`, >= 0 unless bonded) and `shear_force`
/// (N, along `perp(normal)`) are the forces on `j`, and `rolling_moment` (N m,
/// counter-clockwise positive) the rolling resistance's moment on `j` (its
/// opposite acts on `i`), elastic parts only (the optional viscous dashpots,
/// the rolling one too, are not included). `normal_stiffness` is the normal
/// force's tangent stiffness at the overlap, `dF_n / d(overlap)`: what a
/// stiffness estimate (a servo's gain, say) reads instead of assuming a law.
#[derive(Debug, Clone, Default)]
pub struct ContactList {
    /// First particle.
    pub i: Vec<u32>,
    /// Second particle.
    pub j: Vec<u32>,
    /// Contact point (m), middle of the overlap.
    pub point: Vec<Vec2>,
    /// Unit normal from `i` to `j`.
    pub normal: Vec<Vec2>,
    /// Overlap (m); negative for a bond in tension.
    pub overlap: Vec<f64>,
    /// Normal force (N).
    pub normal_force: Vec<f64>,
    /// Shear force (N).
    pub shear_force: Vec<f64>,
    /// Whether the shear force is at the Coulomb cap, `|Fs| = mu Fn` (never for bonds).
    pub sliding: Vec<bool>,
    /// Whether the pair is a bond.
    pub bonded: Vec<bool>,
    /// Rolling moment on `j` (N m), the rolling spring `M_r`: 0 without rolling
    /// resistance and for bonds.
    pub rolling_moment: Vec<f64>,
    /// The normal force's tangent stiffness (N/m): `kn` for the linear law,
    /// `2 E* a` for Hertz-Mindlin, the bond's `kn` for a bond.
    pub normal_stiffness: Vec<f64>,
}

/// Particle-wall contacts, sorted by `(wall, particle)` (external particle
/// indices), in the same consistent state as [`ContactList`]; `normal` points
/// from the wall to the particle and the forces act on the particle.
#[derive(Debug, Clone, Default)]
pub struct WallContactList {
    /// Wall id.
    pub wall: Vec<u32>,
    /// Particle index.
    pub particle: Vec<u32>,
    /// Contact point (m).
    pub point: Vec<Vec2>,
    /// Unit normal from wall to particle.
    pub normal: Vec<Vec2>,
    /// Overlap (m).
    pub overlap: Vec<f64>,
    /// Normal force on the particle (N).
    pub normal_force: Vec<f64>,
    /// Shear force on the particle (N).
    pub shear_force: Vec<f64>,
    /// Whether the shear force is at the Coulomb cap.
    pub sliding: Vec<bool>,
    /// Rolling moment on the particle (N m, the rolling spring `M_r`; 0
    /// without rolling resistance).
    pub rolling_moment: Vec<f64>,
    /// The normal force's tangent stiffness (N/m), as [`ContactList`]'s.
    pub normal_stiffness: Vec<f64>,
}

impl Simulation {
    /// Current particle-particle contacts (overlap > 0) and all bonds, as the
    /// next force evaluation will compute them (the state is not changed).
    pub fn contacts(&mut self) -> Result<ContactList> {
        self.ensure_neighbors()?;
        let p = &self.particles;
        let pairs = &self.neighbors.pairs;
        let mut rows: Vec<ContactRow> = Vec::new();
        for (k, record) in self.preview_pairs().into_iter().enumerate() {
            if let Some(c) = record {
                let i = pairs.i[k] as usize;
                let point = contact_point(p.position[i], c.normal, p.radius[i], c.overlap);
                rows.push((
                    pairs.i[k],
                    pairs.j[k],
                    point,
                    c.normal,
                    c.overlap,
                    c.elastic_normal,
                    c.shear_spring,
                    c.sliding,
                    false,
                    c.rolling_spring,
                    c.normal_stiffness,
                ));
            }
        }
        for (b, f) in self.bonds.list.iter().zip(self.preview_bonds()) {
            let (i, j) = (b.i as usize, b.j as usize);
            let overlap = p.radius[i] + p.radius[j] - f.distance;
            let point = contact_point(p.position[i], f.normal, p.radius[i], overlap);
            rows.push((
                b.i,
                b.j,
                point,
                f.normal,
                overlap,
                f.normal_force,
                f.shear_force,
                false,
                true,
                0.0,
                b.normal_stiffness,
            ));
        }
        // external indices, i < j: swapping a pair flips its normal and the
        // rolling moment (now on the other disk), and nothing else (the shear
        // force on the new j along the new tangent is unchanged, and the
        // contact point, mid-overlap, is the same seen from either disk)
        for r in rows.iter_mut() {
            let (i, j) = (
                self.external_index(r.0 as usize) as u32,
                self.external_index(r.1 as usize) as u32,
            );
            if i < j {
                (r.0, r.1) = (i, j);
            } else {
                (r.0, r.1) = (j, i);
                r.3 = [-r.3[0], -r.3[1]];
                // (0 - M: a moment of 0 stays +0)
                r.9 = 0.0 - r.9;
            }
        }
        rows.sort_by_key(|r| (r.0, r.1));
        let mut out = ContactList::default();
        for r in rows {
            out.i.push(r.0);
            out.j.push(r.1);
            out.point.push(r.2);
            out.normal.push(r.3);
            out.overlap.push(r.4);
            out.normal_force.push(r.5);
            out.shear_force.push(r.6);
            out.sliding.push(r.7);
            out.bonded.push(r.8);
            out.rolling_moment.push(r.9);
            out.normal_stiffness.push(r.10);
        }
        Ok(out)
    }

    /// Current particle-wall contacts, as the next force evaluation will compute them.
    pub fn wall_contacts(&mut self) -> Result<WallContactList> {
        self.ensure_neighbors()?;
        let p = &self.particles;
        let mut out = WallContactList::default();
        let wp = &self.neighbors.wall_pairs;
        for (k, record) in self.preview_wall_pairs().into_iter().enumerate() {
            if let Some((g, c)) = record {
                let q = wp.particle[k] as usize;
                out.wall.push(wp.wall[k]);
                out.particle.push(self.external_index(q) as u32);
                out.point.push(contact_point(
                    p.position[q],
                    scale(g.normal, -1.0),
                    p.radius[q],
                    g.overlap,
                ));
                out.normal.push(g.normal);
                out.overlap.push(g.overlap);
                out.normal_force.push(c.elastic_normal);
                out.shear_force.push(c.shear_spring);
                out.sliding.push(c.sliding);
                out.rolling_moment.push(c.rolling_spring);
                out.normal_stiffness.push(c.normal_stiffness);
            }
        }
        let mut idx: Vec<usize> = (0..out.wall.len()).collect();
        idx.sort_by_key(|&k| (out.wall[k], out.particle[k]));
        Ok(WallContactList {
            wall: idx.iter().map(|&k| out.wall[k]).collect(),
            particle: idx.iter().map(|&k| out.particle[k]).collect(),
            point: idx.iter().map(|&k| out.point[k]).collect(),
            normal: idx.iter().map(|&k| out.normal[k]).collect(),
            overlap: idx.iter().map(|&k| out.overlap[k]).collect(),
            normal_force: idx.iter().map(|&k| out.normal_force[k]).collect(),
            shear_force: idx.iter().map(|&k| out.shear_force[k]).collect(),
            sliding: idx.iter().map(|&k| out.sliding[k]).collect(),
            rolling_moment: idx.iter().map(|&k| out.rolling_moment[k]).collect(),
            normal_stiffness: idx.iter().map(|&k| out.normal_stiffness[k]).collect(),
        })
    }
}
