//! Follower loads on chains of boundary particles: a confining pressure that
//! follows a deforming boundary (docs/boundary.md, the paper's flexible membrane).
//!
//! A chain is an ordered list of particles `x_0 .. x_{m-1}` walked with the
//! sample on its right (clockwise around the sample). Particle `k` gets
//! `F_k = p * t / 2 * rotCW(x_{k+1} - x_{k-1})` with unit thickness `t = 1`:
//! the pressure `p` on the two half-segments next to it, pointing into the
//! sample. The ends are anchored: `a` is the first particle's projection on the
//! start wall's line and `b` the last one's on the end wall's (the particle
//! itself without a wall); the end particles carry the whole segment to their
//! anchor, so the loads sum to `p rotCW(b - a)`: the pressure on the full span,
//! and zero on a closed polygon. They are recomputed every step, so they follow
//! the bulging boundary.
use serde::{Deserialize, Serialize};

use crate::parallel::StripeLists;
use crate::vec2::{dot, scale, sub, Vec2};
use crate::wall::{Wall, WallShape};

/// One chain of boundary particles under a follower pressure.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PressureChain {
    /// Particles in order, sample on the right (internal indices).
    pub particles: Vec<u32>,
    /// Pressure (Pa), compression positive.
    pub pressure: f64,
    /// Wall whose line anchors the start of the chain.
    pub start_wall: Option<u32>,
    /// Wall whose line anchors the end of the chain.
    pub end_wall: Option<u32>,
}

/// Projection of `x` on the line of `wall`.
pub fn anchor_on(wall: &Wall, x: Vec2) -> Vec2 {
    let (point, normal) = match wall.shape {
        WallShape::Segment { a, .. } => (a, wall.inward_normal()),
        WallShape::Line { point, normal } => (point, normal),
    };
    sub(x, scale(normal, dot(sub(x, point), normal)))
}

impl PressureChain {
    /// Renumbers particles after a reorder (`new_of_old[old] = new`).
    pub fn remap(&mut self, new_of_old: &[u32]) {
        for q in self.particles.iter_mut() {
            *q = new_of_old[*q as usize];
        }
    }

    /// Adds the chain's follower loads to `load` (indexed by particle).
    pub fn apply(&self, position: &[Vec2], walls: &[Wall], load: &mut [Vec2]) {
        for (k, &q) in self.particles.iter().enumerate() {
            self.add_load_of(k, position, walls, &mut load[q as usize]);
        }
    }

    /// Adds the follower load of the chain's `k`-th particle to `load`: the
    /// pressure on the half-segments next to it, and for an end particle the
    /// segment to its anchor, added in this order.
    #[inline]
    pub fn add_load_of(&self, k: usize, position: &[Vec2], walls: &[Wall], load: &mut Vec2) {
        let m = self.particles.len();
        if m == 0 || self.pressure == 0.0 {
            return;
        }
        let at = |k: usize| position[self.particles[k] as usize];
        let start = || match self.start_wall {
            Some(w) => anchor_on(&walls[w as usize], at(0)),
            None => at(0),
        };
        let end = || match self.end_wall {
            Some(w) => anchor_on(&walls[w as usize], at(m - 1)),
            None => at(m - 1),
        };
        let p = self.pressure;
        let mut add = |d: Vec2, factor: f64| {
            // rotCW(d) = (d_y, -d_x)
            load[0] += factor * d[1];
            load[1] -= factor * d[0];
        };
        if m == 1 {
            add(sub(end(), start()), p);
        } else if k == 0 {
            add(sub(at(1), at(0)), 0.5 * p);
            add(sub(at(0), start()), p);
        } else if k == m - 1 {
            add(sub(at(m - 1), at(m - 2)), 0.5 * p);
            add(sub(end(), at(m - 1)), p);
        } else {
            add(sub(at(k + 1), at(k - 1)), 0.5 * p);
        }
    }
}

/// The entries `(chain, k)` of the pressure chains whose particle lies in each
/// stripe of particles, in chain order then `k` order: the order in which
/// [`PressureChain::apply`] over the chains in turn adds to each particle, so a
/// stripe's loads can be computed apart with the same bits.
#[derive(Debug, Clone, Default)]
pub(crate) struct ChainStripes {
    /// `(chain, position in the chain)` per stripe.
    lists: StripeLists<(u32, u32)>,
}

impl ChainStripes {
    /// The entries of `chains` per stripe of `stripe_ranges` (contiguous, in
    /// order); none when the stripes do not cover the chains' particles.
    pub(crate) fn new(chains: &[PressureChain], stripe_ranges: &[(usize, usize)]) -> Self {
        let items = chains.iter().enumerate().flat_map(|(c, chain)| {
            (chain.particles.iter().enumerate())
                .map(move |(k, &q)| (q as usize, (c as u32, k as u32)))
        });
        // stripes of an older list: the rebuild before the next step makes new ones
        let lists = StripeLists::new(stripe_ranges, items).unwrap_or_default();
        ChainStripes { lists }
    }

    /// The number of stripes the index serves (0 when never built).
    pub(crate) fn n_stripes(&self) -> usize {
        self.lists.n_stripes()
    }

    /// Sets the loads of stripe `b`'s particles `lo..hi` (`load` holds them from
    /// `lo`): zero, plus the follower loads of the chains.
    pub(crate) fn stripe_loads(
        &self,
        b: usize,
        lo: usize,
        chains: &[PressureChain],
        position: &[Vec2],
        walls: &[Wall],
        load: &mut [Vec2],
    ) {
        load.fill([0.0; 2]);
        for &(c, k) in self.lists.of_stripe(b) {
            let chain = &chains[c as usize];
            let (k, ps) = (k as usize, chain.particles.as_slice());
            let q = ps[k] as usize - lo;
            if k > 0 && k + 1 < ps.len() && chain.pressure != 0.0 {
                // an inner particle, as `add_load_of` adds it
                let d = sub(position[ps[k + 1] as usize], position[ps[k - 1] as usize]);
                let factor = 0.5 * chain.pressure;
                load[q][0] += factor * d[1];
                load[q][1] -= factor * d[0];
            } else {
                chain.add_load_of(k, position, walls, &mut load[q]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_chain_carries_pressure_times_span() {
        // a vertical chain from y = 0 to y = 1 (walked upwards, sample on the right: +x)
        let position: Vec<Vec2> = (0..11).map(|k| [0.0, k as f64 * 0.1]).collect();
        let chain = PressureChain {
            particles: (0..11).collect(),
            pressure: 100.0,
            start_wall: None,
            end_wall: None,
        };
        let mut load = vec![[0.0; 2]; 11];
        chain.apply(&position, &[], &mut load);
        let total: f64 = load.iter().map(|f| f[0]).sum();
        // without anchors the chain spans its end particles: 1.0 m, half segments at the ends
        assert!((total - 100.0 * 1.0).abs() < 1e-12, "{total}");
        assert!(load.iter().all(|f| f[1].abs() < 1e-12 && f[0] > 0.0));
        assert!((load[5][0] - 100.0 * 0.1).abs() < 1e-12);
    }

    #[test]
    fn anchored_chain_carries_pressure_on_the_span_between_walls() {
        // particles at y = 0.05 .. 0.95 between a floor (y = 0) and a ceiling (y = 1)
        let floor = Wall::new(
            WallShape::Line {
                point: [0.0, 0.0],
                normal: [0.0, 1.0],
            },
            1,
        )
        .unwrap();
        let ceiling = Wall::new(
            WallShape::Line {
                point: [0.0, 1.0],
                normal: [0.0, -1.0],
            },
            1,
        )
        .unwrap();
        let position: Vec<Vec2> = (0..10).map(|k| [0.3, 0.05 + k as f64 * 0.1]).collect();
        let chain = PressureChain {
            particles: (0..10).collect(),
            pressure: 2.0e5,
            start_wall: Some(0),
            end_wall: Some(1),
        };
        let mut load = vec![[0.0; 2]; 10];
        chain.apply(&position, &[floor, ceiling], &mut load);
        let total: f64 = load.iter().map(|f| f[0]).sum();
        assert!((total - 2.0e5 * 1.0).abs() < 1e-9, "{total}");
        // end particles: half a segment (0.05 m) plus the gap to their wall (0.05 m)
        assert!((load[0][0] - 2.0e5 * 0.1).abs() < 1e-9);
        assert!((load[9][0] - 2.0e5 * 0.1).abs() < 1e-9);
    }

    #[test]
    fn load_follows_a_bulging_boundary() {
        // a chain bent outwards (to -x) at its middle: the loads stay normal to it
        let position: Vec<Vec2> = vec![[0.0, 0.0], [-0.1, 0.5], [0.0, 1.0]];
        let chain = PressureChain {
            particles: vec![0, 1, 2],
            pressure: 1.0,
            start_wall: None,
            end_wall: None,
        };
        let mut load = vec![[0.0; 2]; 3];
        chain.apply(&position, &[], &mut load);
        // first segment (0,0)->(-0.1,0.5): its right normal is (0.5, 0.1)/|.|; half of it on each end
        assert!((load[0][0] - 0.25).abs() < 1e-12 && (load[0][1] - 0.05).abs() < 1e-12);
        assert!((load[1][0] - 0.5).abs() < 1e-12 && load[1][1].abs() < 1e-12);
        let total = [
            load.iter().map(|f| f[0]).sum::<f64>(),
            load.iter().map(|f| f[1]).sum::<f64>(),
        ];
        assert!((total[0] - 1.0).abs() < 1e-12 && total[1].abs() < 1e-12);
    }
}
