//! Fabric kernels (docs/fabric.md): the contact-normal histogram, the second
//! Fourier moment of the normals, the fabric tensor and the rattlers.
use rayon::prelude::*;

use super::{mod_two_pi, require_all_finite, require_indices, require_len, CHUNK, TWO_PI};
use crate::error::{EngineError, Result};

/// Sums of the second Fourier moment: `S = sum w sin 2 theta`,
/// `C = sum w cos 2 theta`, `W = sum w`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FourierMoment {
    /// `sum w sin 2 theta`.
    pub sin_sum: f64,
    /// `sum w cos 2 theta`.
    pub cos_sum: f64,
    /// `sum w` (the number of angles without weights).
    pub total: f64,
}

fn check_weights(weights: Option<&[f64]>, n: usize) -> Result<()> {
    if let Some(w) = weights {
        require_len("weights", w.len(), n, "angle")?;
        require_all_finite("weights", w)?;
    }
    Ok(())
}

/// Per-piece partial results of `f`, merged in piece order by `merge`.
fn fold_pieces<T: Send, F, M>(n: usize, f: F, merge: M) -> Option<T>
where
    F: Fn(std::ops::Range<usize>) -> T + Sync,
    M: Fn(T, T) -> T,
{
    let pieces: Vec<T> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|p| f(p * CHUNK..((p + 1) * CHUNK).min(n)))
        .collect();
    pieces.into_iter().reduce(merge)
}

/// Histogram of contact normals over `[0, 2 pi)` in `bins` bins, each angle
/// counted in both directions (`theta` and `theta + pi`), each direction with
/// half its weight in the bin that holds it and half in the same bin, or,
/// within `edge_tolerance` (rad) of a bin edge, half in each of the two bins
/// beside the edge. Weights default to 1.
pub fn angular_histogram(
    angles: &[f64],
    weights: Option<&[f64]>,
    bins: usize,
    edge_tolerance: f64,
) -> Result<Vec<f64>> {
    if bins < 2 {
        return Err(EngineError::invalid(
            "bins",
            format!("must be >= 2, got {bins}"),
        ));
    }
    let width = TWO_PI / bins as f64;
    if !(edge_tolerance >= 0.0 && edge_tolerance < 0.5 * width) {
        return Err(EngineError::invalid(
            "edge_tolerance",
            format!(
                "must be >= 0 and below half a bin ({} rad), got {edge_tolerance}",
                0.5 * width
            ),
        ));
    }
    require_all_finite("angles", angles)?;
    check_weights(weights, angles.len())?;
    let nbins = bins as i64;
    let histogram = fold_pieces(
        angles.len(),
        |range| {
            let mut values = vec![0.0; bins];
            for k in range {
                let half = 0.5 * weights.map_or(1.0, |w| w[k]);
                let a = mod_two_pi(angles[k]);
                for end in [a, mod_two_pi(a + std::f64::consts::PI)] {
                    // u >= 0: truncation is the floor, and the nearest edge
                    // rounds half to even, as NumPy's rint does
                    let u = end / width;
                    let floor = u as i64;
                    let fraction = u - floor as f64;
                    let edge = if fraction > 0.5 || (fraction == 0.5 && floor % 2 == 1) {
                        floor + 1
                    } else {
                        floor
                    };
                    let (lower, upper) = if (u - edge as f64).abs() * width < edge_tolerance {
                        (edge - 1, edge)
                    } else {
                        (floor, floor)
                    };
                    values[lower.rem_euclid(nbins) as usize] += half;
                    values[upper.rem_euclid(nbins) as usize] += half;
                }
            }
            values
        },
        |mut a, b| {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
            a
        },
    );
    Ok(histogram.unwrap_or_else(|| vec![0.0; bins]))
}

/// The sums of the second Fourier moment of `angles` (rad), weights default 1.
pub fn fourier_moment(angles: &[f64], weights: Option<&[f64]>) -> Result<FourierMoment> {
    require_all_finite("angles", angles)?;
    check_weights(weights, angles.len())?;
    let zero = FourierMoment {
        sin_sum: 0.0,
        cos_sum: 0.0,
        total: 0.0,
    };
    let sums = fold_pieces(
        angles.len(),
        |range| {
            let mut m = zero;
            for k in range {
                let w = weights.map_or(1.0, |w| w[k]);
                let (s, c) = (2.0 * angles[k]).sin_cos();
                m.sin_sum += w * s;
                m.cos_sum += w * c;
                m.total += w;
            }
            m
        },
        |a, b| FourierMoment {
            sin_sum: a.sin_sum + b.sin_sum,
            cos_sum: a.cos_sum + b.cos_sum,
            total: a.total + b.total,
        },
    );
    Ok(sums.unwrap_or(zero))
}

/// The 2D fabric tensor `sum w n (x) n / sum w` of unit `normals` and the
/// weight total `sum w` (weights default 1); NaN when empty or `sum w <= 0`.
pub fn fabric_tensor(
    normals: &[[f64; 2]],
    weights: Option<&[f64]>,
) -> Result<([[f64; 2]; 2], f64)> {
    check_weights(weights, normals.len())?;
    if let Some(k) = normals
        .iter()
        .position(|n| !(n[0].is_finite() && n[1].is_finite()))
    {
        return Err(EngineError::invalid(
            format!("normals[{k}]"),
            format!("must be finite, got {:?}", normals[k]),
        ));
    }
    let sums = fold_pieces(
        normals.len(),
        |range| {
            let mut s = [0.0; 4];
            for k in range {
                let w = weights.map_or(1.0, |w| w[k]);
                let [x, y] = normals[k];
                s[0] += w * (x * x);
                s[1] += w * (y * y);
                s[2] += w * (x * y);
                s[3] += w;
            }
            s
        },
        |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]],
    )
    .unwrap_or([0.0; 4]);
    let total = sums[3];
    if normals.is_empty() || total <= 0.0 {
        return Ok(([[f64::NAN; 2]; 2], total));
    }
    let (xx, yy, xy) = (sums[0] / total, sums[1] / total, sums[2] / total);
    Ok(([[xx, xy], [xy, yy]], total))
}

/// The rattlers: particles left with fewer than `min_contacts` contacts once
/// the rattlers among their neighbours are removed, iteratively.
///
/// `contact_i[k] < n_particles` and `contact_j[k]` are the ends of contact
/// `k`; a negative `contact_j` (a wall) counts for `contact_i` only and is
/// never removed. Only particles with `candidates[p]` (all by default) may be
/// removed. The result is the unique largest set of remaining particles in
/// which every candidate keeps `min_contacts` contacts, whatever the order of
/// removal.
pub fn rattlers(
    contact_i: &[i64],
    contact_j: &[i64],
    n_particles: usize,
    min_contacts: usize,
    candidates: Option<&[bool]>,
) -> Result<Vec<bool>> {
    require_len("contact_j", contact_j.len(), contact_i.len(), "contact")?;
    if let Some(c) = candidates {
        require_len("candidates", c.len(), n_particles, "particle")?;
    }
    require_indices("contact_i", contact_i, n_particles, "contact")?;
    let n = n_particles as i64;
    if let Some(k) = contact_j.iter().position(|&p| p >= n) {
        // a negative contact_j is a wall
        return Err(EngineError::invalid(
            "contact_j",
            format!(
                "index {} out of range [0, {n}) at contact {k}",
                contact_j[k]
            ),
        ));
    }
    // contacts per particle, and each particle's particle neighbours (CSR)
    let mut count = vec![0usize; n_particles];
    let mut start = vec![0usize; n_particles + 1];
    for (&a, &b) in contact_i.iter().zip(contact_j) {
        count[a as usize] += 1;
        if b >= 0 {
            count[b as usize] += 1;
            start[a as usize + 1] += 1;
            start[b as usize + 1] += 1;
        }
    }
    for p in 0..n_particles {
        start[p + 1] += start[p];
    }
    let mut fill = start.clone();
    let mut neighbour = vec![0usize; start[n_particles]];
    for (&a, &b) in contact_i.iter().zip(contact_j) {
        if b >= 0 {
            let (a, b) = (a as usize, b as usize);
            neighbour[fill[a]] = b;
            fill[a] += 1;
            neighbour[fill[b]] = a;
            fill[b] += 1;
        }
    }
    drop(fill);
    let removable = |p: usize| candidates.is_none_or(|c| c[p]);
    let mut queued = vec![false; n_particles];
    let mut removed = vec![false; n_particles];
    let mut queue: Vec<usize> = (0..n_particles)
        .filter(|&p| removable(p) && count[p] < min_contacts)
        .collect();
    for &p in &queue {
        queued[p] = true;
    }
    while let Some(p) = queue.pop() {
        removed[p] = true;
        for &q in &neighbour[start[p]..start[p + 1]] {
            if removed[q] {
                continue;
            }
            count[q] -= 1;
            if !queued[q] && removable(q) && count[q] < min_contacts {
                queued[q] = true;
                queue.push(q);
            }
        }
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn histogram_halves_on_edges() {
        // 0 sits on an edge, pi / 4 in the middle of a bin of 4
        let h = angular_histogram(&[0.0, PI / 4.0], None, 4, 1e-9).unwrap();
        assert_eq!(h, vec![1.5, 0.5, 1.5, 0.5]);
        assert!(angular_histogram(&[0.0], None, 1, 0.0).is_err());
        assert!(angular_histogram(&[0.0], None, 4, 1.0).is_err());
    }

    #[test]
    fn moment_and_tensor_of_a_square_lattice_are_isotropic() {
        let angles = [0.0, PI / 2.0, PI, 1.5 * PI];
        let m = fourier_moment(&angles, None).unwrap();
        assert!(m.sin_sum.abs() < 1e-15 && m.cos_sum.abs() < 1e-15 && m.total == 4.0);
        let normals: Vec<[f64; 2]> = angles.iter().map(|a| [a.cos(), a.sin()]).collect();
        let (phi, total) = fabric_tensor(&normals, None).unwrap();
        assert_eq!(total, 4.0);
        assert!((phi[0][0] - 0.5).abs() < 1e-15 && phi[0][1].abs() < 1e-15);
        assert!(fabric_tensor(&[], None).unwrap().0[0][0].is_nan());
    }

    #[test]
    fn rattlers_are_removed_iteratively() {
        // a chain 0-1-2-3 hanging off a triangle 3-4-5: the chain peels off one by one
        let ci = [0, 1, 2, 3, 4, 5];
        let cj = [1, 2, 3, 4, 5, 3];
        let r = rattlers(&ci, &cj, 6, 2, None).unwrap();
        assert_eq!(r, vec![true, true, true, false, false, false]);
        // a wall keeps particle 0 in: 0 has the wall and 1
        let r = rattlers(&[0, 0, 1, 2, 3, 4, 5], &[-1, 1, 2, 3, 4, 5, 3], 6, 2, None).unwrap();
        assert_eq!(r, vec![false; 6]);
        let keep = [false, true, true, true, true, true];
        let r = rattlers(&ci, &cj, 6, 2, Some(&keep)).unwrap();
        assert_eq!(r, vec![false; 6]);
    }

    #[test]
    fn sums_are_independent_of_thread_count() {
        let angles: Vec<f64> = (0..5 * CHUNK + 3)
            .map(|k| (k as f64 * 0.7).sin() * 4.0)
            .collect();
        let weights: Vec<f64> = (0..angles.len())
            .map(|k| 1.0 + (k % 13) as f64 * 0.37)
            .collect();
        let run = |threads| {
            crate::analysis::with_threads(threads, || {
                (
                    angular_histogram(&angles, Some(&weights), 18, 1e-9).unwrap(),
                    fourier_moment(&angles, Some(&weights)).unwrap(),
                )
            })
            .unwrap()
        };
        assert_eq!(run(1), run(2));
    }
}
