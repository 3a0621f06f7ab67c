//! The current contacts as parallel arrays, for output and analysis.
use crate::contact::{contact_point, disk_disk};
use crate::error::Result;
use crate::pipeline::{minimum_image, Simulation};
use crate::vec2::{add, norm, scale, sub, Vec2};

/// One row of the contact table while it is assembled.
type ContactRow = (u32, u32, Vec2, Vec2, f64, f64, f64, bool, bool);

/// Particle-particle contacts and bonds, sorted by `(i, j)` with `i < j`,
/// in external (user) particle indices.
///
/// `normal` points from `i` to `j`; `normal_force` (N, >= 0 unless bonded) and
/// `shear_force` (N, along `perp(normal)`) are the forces on `j`, elastic parts
/// only (viscous dashpot forces are not included).
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
    /// Whether the contact slid in the last step.
    pub sliding: Vec<bool>,
    /// Whether the pair is a bond.
    pub bonded: Vec<bool>,
}

/// Particle-wall contacts, sorted by `(wall, particle)` (external particle
/// indices); `normal` points from the wall to the particle.
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
    /// Whether the contact slid in the last step.
    pub sliding: Vec<bool>,
}

impl Simulation {
    /// Current particle-particle contacts (overlap > 0) and all bonds.
    pub fn contacts(&mut self) -> Result<ContactList> {
        self.ensure_neighbors()?;
        let p = &self.particles;
        let pairs = &self.neighbors.pairs;
        let mut rows: Vec<ContactRow> = Vec::new();
        for k in 0..pairs.len() {
            let (i, j) = (pairs.i[k] as usize, pairs.j[k] as usize);
            let offset = match &self.cell {
                Some(c) => c.image_offset(pairs.shift[k]),
                None => [0.0; 2],
            };
            let d = sub(add(p.position[j], offset), p.position[i]);
            let g = disk_disk(d, p.radius[i], p.radius[j]);
            if g.overlap > 0.0 {
                let kn = self.materials.by_index(pairs.model[k]).normal_stiffness;
                let point = contact_point(p.position[i], g.normal, p.radius[i], g.overlap);
                rows.push((
                    pairs.i[k],
                    pairs.j[k],
                    point,
                    g.normal,
                    g.overlap,
                    kn * g.overlap,
                    pairs.shear[k],
                    pairs.sliding[k],
                    false,
                ));
            }
        }
        for b in &self.bonds.list {
            let (i, j) = (b.i as usize, b.j as usize);
            let d = minimum_image(self.cell.as_ref(), sub(p.position[j], p.position[i]));
            let dist = norm(d);
            let normal = scale(d, 1.0 / dist);
            let overlap = p.radius[i] + p.radius[j] - dist;
            let point = contact_point(p.position[i], normal, p.radius[i], overlap);
            let fn_ = b.normal_stiffness * (b.rest_length - dist);
            rows.push((b.i, b.j, point, normal, overlap, fn_, b.shear, false, true));
        }
        // external indices, i < j: swapping a pair flips its normal, and nothing
        // else (the shear force on the new j along the new tangent is unchanged,
        // and the contact point, mid-overlap, is the same seen from either disk)
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
        }
        Ok(out)
    }

    /// Current particle-wall contacts.
    pub fn wall_contacts(&mut self) -> Result<WallContactList> {
        self.ensure_neighbors()?;
        let p = &self.particles;
        let mut out = WallContactList::default();
        let wp = &self.neighbors.wall_pairs;
        let candidates =
            (0..wp.wall.len()).map(|k| (wp.wall[k], wp.particle[k], wp.shear[k], wp.sliding[k]));
        for (w, q, shear, sliding) in candidates {
            let wall = &self.walls[w as usize];
            let x = p.position[q as usize];
            let r = p.radius[q as usize];
            let g = wall.disk_contact(x, r);
            if g.overlap > 0.0 {
                let kn = self
                    .materials
                    .get(wall.group, p.group[q as usize])
                    .normal_stiffness;
                out.wall.push(w);
                out.particle.push(self.external_index(q as usize) as u32);
                out.point
                    .push(contact_point(x, scale(g.normal, -1.0), r, g.overlap));
                out.normal.push(g.normal);
                out.overlap.push(g.overlap);
                out.normal_force.push(kn * g.overlap);
                out.shear_force.push(shear);
                out.sliding.push(sliding);
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
        })
    }
}
