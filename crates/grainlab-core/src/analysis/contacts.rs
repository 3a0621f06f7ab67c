//! Contacts from geometry: every pair of disks closer than the sum of their
//! radii plus a tolerance, found with a cell list; and the contact normals.
//!
//! A pair `i < j` is in contact when `|x_j - x_i| < (r_i + r_j) + tolerance`,
//! the separation taken as the minimum image in periodic directions, where the
//! coordinates are first wrapped into the box (`(x - lo) mod L`, as the NumPy
//! reference does). Heights (a third coordinate, never periodic) make it the
//! test of spheres. Pairs come out sorted by `i`, then `j`.
use rayon::prelude::*;

use super::{require_all_finite, require_indices, require_len, CHUNK};
use crate::error::{require_finite, require_non_negative, EngineError, Result};

/// One periodic direction of the box: its lower bound and its length (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodicAxis {
    /// Lower bound of the box in this direction (m).
    pub lo: f64,
    /// Length of the box in this direction (m), > 0.
    pub length: f64,
}

/// Contact pairs as parallel arrays, `i[k] < j[k]`, sorted by `i` then `j`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ContactPairs {
    /// First particle of each pair.
    pub i: Vec<usize>,
    /// Second particle of each pair.
    pub j: Vec<usize>,
}

/// A disk as the cell list stores it: wrapped coordinates, radius, index.
#[derive(Clone, Copy)]
struct Entry {
    x: f64,
    y: f64,
    z: f64,
    radius: f64,
    index: usize,
}

/// One direction of the cell grid.
#[derive(Clone, Copy)]
struct GridAxis {
    origin: f64,
    cell: f64,
    cells: usize,
    periodic: bool,
}

impl GridAxis {
    fn new(values: impl Iterator<Item = f64> + Clone, cutoff: f64, period: Option<f64>) -> Self {
        // cells a little wider than the cut-off, so that round-off in the cell
        // index never separates two disks in range by more than one cell
        let width = cutoff * (1.0 + 1e-9);
        match period {
            Some(length) => GridAxis {
                origin: 0.0,
                cell: 0.0,
                cells: periodic_cells(length / width),
                periodic: true,
            }
            .with_period(length),
            None => {
                let lo = values.clone().fold(f64::INFINITY, f64::min);
                let hi = values.fold(f64::NEG_INFINITY, f64::max);
                let cells = (((hi - lo) / width) as usize).saturating_add(1);
                GridAxis {
                    origin: lo,
                    cell: width,
                    cells,
                    periodic: false,
                }
            }
        }
    }

    fn with_period(mut self, length: f64) -> Self {
        self.cell = length / self.cells as f64;
        self
    }

    /// Widens the cells by `factor` (>= 1).
    fn widen(&mut self, factor: f64, period: Option<f64>) {
        match period {
            Some(length) => {
                self.cells = periodic_cells(self.cells as f64 / factor);
                self.cell = length / self.cells as f64;
            }
            None => {
                let extent = self.cell * self.cells as f64;
                self.cell *= factor;
                self.cells = ((extent / self.cell) as usize).saturating_add(1);
            }
        }
    }

    fn index(&self, value: f64) -> usize {
        let u = (value - self.origin) / self.cell;
        if u <= 0.0 {
            0
        } else {
            // truncation is the floor of a positive value
            (u as usize).min(self.cells - 1)
        }
    }

    /// The cell `offset` (-1, 0 or 1) away from `c`, if there is one.
    fn step(&self, c: usize, offset: isize) -> Option<usize> {
        let k = c as isize + offset;
        if self.periodic {
            Some(k.rem_euclid(self.cells as isize) as usize)
        } else if k < 0 || k >= self.cells as isize {
            None
        } else {
            Some(k as usize)
        }
    }
}

/// Cells along a periodic direction of `fit` cut-offs: 1 or at least 3, so
/// that the cells one step before and after a cell are never the same cell.
fn periodic_cells(fit: f64) -> usize {
    match fit as usize {
        0..=2 => 1,
        n => n,
    }
}

/// `x - L round(x / L)`, the minimum image of a separation (ties to even, as NumPy rounds).
#[inline]
fn minimum_image(d: f64, length: f64) -> f64 {
    // below half a length the rounding gives 0 and `d` comes back unchanged
    if d.abs() < 0.5 * length {
        d
    } else {
        d - length * (d / length).round_ties_even()
    }
}

/// The coordinate wrapped into `[0, L)` as `(x - lo) mod L` (NumPy's `mod`).
#[inline]
fn wrap(x: f64, axis: PeriodicAxis) -> f64 {
    let r = x - axis.lo;
    if (0.0..axis.length).contains(&r) {
        return r;
    }
    let r = r % axis.length;
    let r = if r < 0.0 { r + axis.length } else { r };
    if r >= axis.length {
        0.0
    } else {
        r
    }
}

/// All pairs of disks in contact (module docs), sorted by `i` then `j`.
///
/// `positions` (m) are the centres, `heights` an optional third coordinate
/// (m, never periodic), `radii` (m) > 0, `tolerance` (m) >= 0 is added to the
/// radius sum, and `periodic[a]` gives the box of each periodic direction.
/// Runs in parallel on the current rayon pool; the result does not depend on
/// the number of threads.
pub fn detect_contacts(
    positions: &[[f64; 2]],
    heights: Option<&[f64]>,
    radii: &[f64],
    tolerance: f64,
    periodic: [Option<PeriodicAxis>; 2],
) -> Result<ContactPairs> {
    let n = positions.len();
    require_len("radii", radii.len(), n, "particle")?;
    if let Some(z) = heights {
        require_len("heights", z.len(), n, "particle")?;
        require_all_finite("heights", z)?;
    }
    require_non_negative("tolerance", tolerance)?;
    for (k, p) in positions.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(EngineError::invalid(
                format!("positions[{k}]"),
                format!("must be finite, got {p:?}"),
            ));
        }
    }
    if let Some(k) = radii.iter().position(|r| !(r.is_finite() && *r > 0.0)) {
        return Err(EngineError::invalid(
            format!("radii[{k}]"),
            format!("must be finite and > 0, got {}", radii[k]),
        ));
    }
    for (axis, name) in periodic.iter().zip(["x", "y"]) {
        if let Some(a) = axis {
            require_finite(&format!("box lower bound in {name}"), a.lo)?;
            if !(a.length.is_finite() && a.length > 0.0) {
                return Err(EngineError::invalid(
                    format!("box length in {name}"),
                    format!("must be finite and > 0, got {}", a.length),
                ));
            }
        }
    }
    if n < 2 {
        return Ok(ContactPairs::default());
    }
    let pairs = match heights {
        Some(z) => touching_pairs::<true>(positions, z, radii, tolerance, periodic),
        None => touching_pairs::<false>(positions, &[], radii, tolerance, periodic),
    };
    Ok(sorted_pairs(n, pairs))
}

/// Every touching pair once, as `(lower index, higher index)`, in no useful order.
fn touching_pairs<const SPHERES: bool>(
    positions: &[[f64; 2]],
    heights: &[f64],
    radii: &[f64],
    tolerance: f64,
    periodic: [Option<PeriodicAxis>; 2],
) -> Vec<Vec<(usize, usize)>> {
    let n = positions.len();
    let cutoff = 2.0 * radii.iter().copied().fold(0.0, f64::max) + tolerance;
    let coord = |k: usize, a: usize| match periodic[a] {
        Some(axis) => wrap(positions[k][a], axis),
        None => positions[k][a],
    };
    let entries: Vec<Entry> = (0..n)
        .map(|k| Entry {
            x: coord(k, 0),
            y: coord(k, 1),
            z: if SPHERES { heights[k] } else { 0.0 },
            radius: radii[k],
            index: k,
        })
        .collect();
    let period = [periodic[0].map(|a| a.length), periodic[1].map(|a| a.length)];
    let mut grid = [
        GridAxis::new(entries.iter().map(|e| e.x), cutoff, period[0]),
        GridAxis::new(entries.iter().map(|e| e.y), cutoff, period[1]),
    ];
    // a few far outliers must not make a huge, empty grid
    let limit = (2 * n + 64) as f64;
    let cells = grid[0].cells as f64 * grid[1].cells as f64;
    if cells > limit {
        let factor = (cells / limit).sqrt() * (1.0 + 1e-9);
        grid[0].widen(factor, period[0]);
        grid[1].widen(factor, period[1]);
    }
    let (nx, ny) = (grid[0].cells, grid[1].cells);

    // counting sort of the disks by cell, row after row of cells
    let cell_of: Vec<usize> = entries
        .iter()
        .map(|e| grid[1].index(e.y) * nx + grid[0].index(e.x))
        .collect();
    let mut start = vec![0usize; nx * ny + 1];
    for &c in &cell_of {
        start[c + 1] += 1;
    }
    for c in 0..nx * ny {
        start[c + 1] += start[c];
    }
    let mut fill = start.clone();
    let mut sorted = vec![entries[0]; n];
    for (e, &c) in entries.iter().zip(&cell_of) {
        sorted[fill[c]] = *e;
        fill[c] += 1;
    }
    drop((entries, cell_of, fill));

    // each pair of cells once: a cell with itself, and with the cells after it
    // in the half shell; offsets that land on the same cell (a periodic
    // direction of one cell) are kept once
    let half_shell = |cx: usize, cy: usize| {
        let mut out = [usize::MAX; 4];
        let mut count = 0;
        for (dx, dy) in [(1, 0), (-1, 1), (0, 1), (1, 1)] {
            if let (Some(x), Some(y)) = (grid[0].step(cx, dx), grid[1].step(cy, dy)) {
                let cell = y * nx + x;
                if cell != cy * nx + cx && !out[..count].contains(&cell) {
                    out[count] = cell;
                    count += 1;
                }
            }
        }
        (out, count)
    };
    let test = |a: &Entry, b: &Entry| -> bool {
        let mut dx = b.x - a.x;
        let mut dy = b.y - a.y;
        if let Some(l) = period[0] {
            dx = minimum_image(dx, l);
        }
        if let Some(l) = period[1] {
            dy = minimum_image(dy, l);
        }
        let reach = a.radius + b.radius + tolerance;
        let dz = if SPHERES { b.z - a.z } else { 0.0 };
        let squared = dx * dx + dy * dy + dz * dz;
        // decided by the square away from the threshold; near it by the
        // distance as the reference computes it
        let limit = reach * reach;
        if squared > limit * (1.0 + 1e-9) {
            false
        } else if squared < limit * (1.0 - 1e-9) {
            true
        } else if SPHERES {
            squared.sqrt() < reach
        } else {
            dx.hypot(dy) < reach
        }
    };
    let rows_per_piece = (CHUNK / nx.max(1)).max(1);
    (0..ny.div_ceil(rows_per_piece))
        .into_par_iter()
        .map(|piece| {
            let mut pairs = Vec::new();
            let rows = piece * rows_per_piece..((piece + 1) * rows_per_piece).min(ny);
            for cy in rows {
                for cx in 0..nx {
                    let own = cy * nx + cx;
                    let here = &sorted[start[own]..start[own + 1]];
                    let (others, count) = half_shell(cx, cy);
                    for (k, a) in here.iter().enumerate() {
                        let mut check = |b: &Entry| {
                            if test(a, b) {
                                pairs.push((a.index.min(b.index), a.index.max(b.index)));
                            }
                        };
                        here[k + 1..].iter().for_each(&mut check);
                        for &cell in &others[..count] {
                            sorted[start[cell]..start[cell + 1]]
                                .iter()
                                .for_each(&mut check);
                        }
                    }
                }
            }
            pairs
        })
        .collect()
}

/// The pairs sorted by first, then second particle (counting sort by the
/// first, then each short row sorted).
fn sorted_pairs(n: usize, found: Vec<Vec<(usize, usize)>>) -> ContactPairs {
    let total: usize = found.iter().map(Vec::len).sum();
    let mut row_start = vec![0usize; n + 1];
    for &(i, _) in found.iter().flatten() {
        row_start[i + 1] += 1;
    }
    for k in 0..n {
        row_start[k + 1] += row_start[k];
    }
    let mut fill = row_start.clone();
    let mut j = vec![0usize; total];
    for &(i, jj) in found.iter().flatten() {
        j[fill[i]] = jj;
        fill[i] += 1;
    }
    drop((found, fill));
    let mut i = vec![0usize; total];
    for (row, w) in row_start.windows(2).enumerate() {
        i[w[0]..w[1]].fill(row);
        j[w[0]..w[1]].sort_unstable();
    }
    ContactPairs { i, j }
}

/// Unit normals from `i`'s centre towards `j`'s and their angles.
///
/// The separation is `x_j - x_i`, as the minimum image
/// `d - L round(d / L)` in a direction with `lengths[a] = Some(L)`; the
/// normal is `d / |d|` and the angle `atan2(n_y, n_x)` in `[0, 2 pi)`.
/// (`|d|` is `sqrt(d_x^2 + d_y^2)`, within an ulp of the reference's `hypot`.)
/// Coincident centres are an error naming the contact.
pub fn contact_normals(
    positions: &[[f64; 2]],
    i: &[usize],
    j: &[usize],
    lengths: [Option<f64>; 2],
) -> Result<(Vec<[f64; 2]>, Vec<f64>)> {
    require_len("contact_j", j.len(), i.len(), "contact")?;
    let n = positions.len();
    require_indices("contact_i", i, n, "contact")?;
    require_indices("contact_j", j, n, "contact")?;
    let mut normals = vec![[0.0; 2]; i.len()];
    let mut angles = vec![0.0; i.len()];
    let failures: Vec<Option<usize>> = normals
        .par_chunks_mut(CHUNK)
        .zip(angles.par_chunks_mut(CHUNK))
        .enumerate()
        .map(|(piece, (normals, angles))| {
            let first = piece * CHUNK;
            for (k, (normal, angle)) in normals.iter_mut().zip(angles.iter_mut()).enumerate() {
                let (a, b) = (positions[i[first + k]], positions[j[first + k]]);
                let mut d = [b[0] - a[0], b[1] - a[1]];
                for axis in 0..2 {
                    if let Some(l) = lengths[axis] {
                        d[axis] = minimum_image(d[axis], l);
                    }
                }
                let length = (d[0] * d[0] + d[1] * d[1]).sqrt();
                if length == 0.0 {
                    return Some(first + k);
                }
                *normal = [d[0] / length, d[1] / length];
                *angle = angle_of(*normal);
            }
            None
        })
        .collect();
    if let Some(k) = failures.into_iter().flatten().next() {
        return Err(EngineError::invalid(
            "contact_normal",
            format!("undefined for contact {k} (coincident centres)"),
        ));
    }
    Ok((normals, angles))
}

/// The angle of a normal, `atan2(n_y, n_x)` in `[0, 2 pi)`.
#[inline]
pub(crate) fn angle_of(normal: [f64; 2]) -> f64 {
    let a = normal[1].atan2(normal[0]);
    let a = if a < 0.0 { a + super::TWO_PI } else { a };
    if a >= super::TWO_PI {
        0.0
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute_force(
        positions: &[[f64; 2]],
        radii: &[f64],
        tolerance: f64,
        lengths: [Option<f64>; 2],
    ) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for i in 0..positions.len() {
            for j in i + 1..positions.len() {
                let mut d = [
                    positions[j][0] - positions[i][0],
                    positions[j][1] - positions[i][1],
                ];
                for a in 0..2 {
                    if let Some(l) = lengths[a] {
                        d[a] = minimum_image(d[a], l);
                    }
                }
                if d[0].hypot(d[1]) < radii[i] + radii[j] + tolerance {
                    out.push((i, j));
                }
            }
        }
        out
    }

    fn random_disks(n: usize, side: f64, seed: u64) -> (Vec<[f64; 2]>, Vec<f64>) {
        let mut state = seed;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let positions = (0..n).map(|_| [side * next(), side * next()]).collect();
        let radii = (0..n).map(|_| 0.5 + next()).collect();
        (positions, radii)
    }

    #[test]
    fn matches_brute_force_open_and_periodic() {
        let (positions, radii) = random_disks(700, 30.0, 7);
        for periodic in [[false, false], [true, false], [false, true], [true, true]] {
            let axes = periodic.map(|p| {
                p.then_some(PeriodicAxis {
                    lo: 0.0,
                    length: 30.0,
                })
            });
            let got = detect_contacts(&positions, None, &radii, 0.01, axes).unwrap();
            let lengths = periodic.map(|p| p.then_some(30.0));
            let want = brute_force(&positions, &radii, 0.01, lengths);
            let pairs: Vec<(usize, usize)> =
                got.i.iter().copied().zip(got.j.iter().copied()).collect();
            assert_eq!(pairs, want, "periodic {periodic:?}");
        }
    }

    #[test]
    fn small_periodic_boxes_count_each_pair_once() {
        // boxes of one to four cut-offs (3.1 here): one, two, three, four cells
        for (side, seed) in [(3.5, 3), (7.0, 4), (10.0, 5), (13.0, 6)] {
            let (positions, radii) = random_disks(40, side, seed);
            let radii: Vec<f64> = radii.iter().map(|r| r.min(1.5)).collect();
            let axes = [Some(PeriodicAxis {
                lo: -1.0,
                length: side,
            }); 2];
            let shifted: Vec<[f64; 2]> =
                positions.iter().map(|p| [p[0] - 1.0, p[1] - 1.0]).collect();
            let got = detect_contacts(&shifted, None, &radii, 0.1, axes).unwrap();
            let want = brute_force(&positions, &radii, 0.1, [Some(side); 2]);
            let pairs: Vec<(usize, usize)> =
                got.i.iter().copied().zip(got.j.iter().copied()).collect();
            assert!(!want.is_empty());
            assert_eq!(pairs, want, "side {side}");
        }
    }

    #[test]
    fn independent_of_thread_count() {
        let (positions, radii) = random_disks(60_000, 400.0, 11);
        let axes = [
            Some(PeriodicAxis {
                lo: 0.0,
                length: 400.0,
            }),
            None,
        ];
        let one = super::super::with_threads(1, || {
            detect_contacts(&positions, None, &radii, 0.0, axes).unwrap()
        })
        .unwrap();
        let two = super::super::with_threads(2, || {
            detect_contacts(&positions, None, &radii, 0.0, axes).unwrap()
        })
        .unwrap();
        assert!(!one.i.is_empty());
        assert_eq!(one, two);
    }

    #[test]
    fn far_outlier_does_not_blow_up_the_grid() {
        let mut positions = vec![[0.0, 0.0], [1.5, 0.0], [1e12, 1e12]];
        positions.push([1e12 + 1.0, 1e12]);
        let radii = vec![1.0; 4];
        let got = detect_contacts(&positions, None, &radii, 0.0, [None, None]).unwrap();
        assert_eq!((got.i, got.j), (vec![0, 2], vec![1, 3]));
    }

    #[test]
    fn bad_input_is_named() {
        let err = detect_contacts(&[[0.0, f64::NAN]], None, &[1.0], 0.0, [None, None]);
        assert!(err.unwrap_err().to_string().starts_with("positions[0]"));
        let err = detect_contacts(
            &[[0.0, 0.0], [1.0, 0.0]],
            None,
            &[1.0, -1.0],
            0.0,
            [None, None],
        );
        assert!(err.unwrap_err().to_string().starts_with("radii[1]"));
        let err = detect_contacts(&[[0.0, 0.0]], None, &[1.0], -1.0, [None, None]);
        assert!(err.unwrap_err().to_string().starts_with("tolerance"));
    }

    #[test]
    fn normals_use_the_minimum_image() {
        let positions = [[0.5, 0.0], [9.5, 0.0]];
        let (normals, angles) =
            contact_normals(&positions, &[0], &[1], [Some(10.0), None]).unwrap();
        assert_eq!(normals, vec![[-1.0, 0.0]]);
        assert_eq!(angles, vec![std::f64::consts::PI]);
        let err = contact_normals(&[[0.0, 0.0], [0.0, 0.0]], &[0], &[1], [None, None]);
        assert!(err.is_err());
    }
}
