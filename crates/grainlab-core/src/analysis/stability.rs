//! The geometrical stability index lambda of every particle (docs/fabric.md).
//!
//! For a particle with `n >= 2` contacts at angles sorted counter-clockwise,
//! `phi_0 <= ... <= phi_{n-1}` in `[0, 2 pi)`, and `e_j = phi_j - 2 pi j / n`,
//! the deviation from the stable arrangement started at contact `k` is
//! `dS(k) = sum_j min(|e_j - e_k|, 2 pi - |e_j - e_k|)` (Eq. 9), `D = min_k dS(k)`
//! (Eq. 10) and `lambda = D / 2 pi` (Eq. 11). A particle with 0 or 1 contact
//! has `lambda = 1`.
use rayon::prelude::*;

use super::{mod_two_pi, require_indices, require_len, CHUNK, TWO_PI};
use crate::error::{EngineError, Result};

/// Contacts a particle may have before its angles are sorted on the heap.
const INLINE_CONTACTS: usize = 16;

/// lambda (module docs) and the number of contact ends of every particle.
///
/// `owner[k]` is the particle (`< n_particles`) of contact end `k` and
/// `angles[k]` (rad, finite, any real value: taken modulo 2 pi) its angle on
/// that particle; a particle–particle contact gives one end on each of its
/// particles. The order of the ends does not matter. Runs in parallel on the
/// current rayon pool; the result does not depend on the number of threads.
pub fn stability_index(
    owner: &[usize],
    angles: &[f64],
    n_particles: usize,
) -> Result<(Vec<f64>, Vec<usize>)> {
    require_len("angles", angles.len(), owner.len(), "contact end")?;
    require_indices("owner", owner, n_particles, "end")?;
    if let Some(k) = angles.iter().position(|a| !a.is_finite()) {
        return Err(EngineError::invalid(
            format!("angles[{k}]"),
            format!("must be finite, got {}", angles[k]),
        ));
    }
    // the ends of each particle side by side (counting sort by owner)
    let mut start = vec![0usize; n_particles + 1];
    for &p in owner {
        start[p + 1] += 1;
    }
    for p in 0..n_particles {
        start[p + 1] += start[p];
    }
    let mut fill = start.clone();
    let mut grouped = vec![0.0; angles.len()];
    for (&p, &a) in owner.iter().zip(angles) {
        grouped[fill[p]] = a;
        fill[p] += 1;
    }
    Ok(lambda_of_groups(&start, &grouped))
}

/// lambda and the contact counts from particle–particle contacts alone.
///
/// Contact `k` between `contact_i[k]` and `contact_j[k]` (both
/// `< n_particles`) at angle `angles[k]` (rad, in `[0, 2 pi)`, on `i`) gives
/// one end at that angle on `i` and one at the opposite angle on `j`
/// (`angle + pi`, less `2 pi` from `2 pi` on), the ends [`stability_index`]
/// takes for such a snapshot.
pub fn stability_index_of_contacts(
    contact_i: &[usize],
    contact_j: &[usize],
    angles: &[f64],
    n_particles: usize,
) -> Result<(Vec<f64>, Vec<usize>)> {
    require_len("contact_j", contact_j.len(), contact_i.len(), "contact")?;
    require_len("angles", angles.len(), contact_i.len(), "contact")?;
    require_indices("contact_i", contact_i, n_particles, "contact")?;
    require_indices("contact_j", contact_j, n_particles, "contact")?;
    if let Some(k) = angles.iter().position(|a| !(0.0..TWO_PI).contains(a)) {
        return Err(EngineError::invalid(
            format!("angles[{k}]"),
            format!("must be in [0, 2 pi), got {}", angles[k]),
        ));
    }
    let mut start = vec![0usize; n_particles + 1];
    for (&a, &b) in contact_i.iter().zip(contact_j) {
        start[a + 1] += 1;
        start[b + 1] += 1;
    }
    for p in 0..n_particles {
        start[p + 1] += start[p];
    }
    let mut fill = start.clone();
    let mut grouped = vec![0.0; 2 * angles.len()];
    for ((&a, &b), &angle) in contact_i.iter().zip(contact_j).zip(angles) {
        grouped[fill[a]] = angle;
        fill[a] += 1;
        let opposite = angle + std::f64::consts::PI;
        grouped[fill[b]] = if opposite >= TWO_PI {
            opposite - TWO_PI
        } else {
            opposite
        };
        fill[b] += 1;
    }
    Ok(lambda_of_groups(&start, &grouped))
}

/// lambda and the counts of particles whose ends are `grouped[start[p]..start[p + 1]]`.
fn lambda_of_groups(start: &[usize], grouped: &[f64]) -> (Vec<f64>, Vec<usize>) {
    let n_particles = start.len() - 1;
    let counts: Vec<usize> = start.windows(2).map(|w| w[1] - w[0]).collect();
    let mut lambda = vec![1.0; n_particles];
    lambda
        .par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(piece, out)| {
            let mut heap = Vec::new();
            for (k, value) in out.iter_mut().enumerate() {
                let p = piece * CHUNK + k;
                let ends = &grouped[start[p]..start[p + 1]];
                if ends.len() >= 2 {
                    *value = deviation(ends, &mut heap) / TWO_PI;
                }
            }
        });
    (lambda, counts)
}

/// `D` (rad) of one particle from the angles of its `n >= 2` contacts.
fn deviation(ends: &[f64], heap: &mut Vec<f64>) -> f64 {
    let n = ends.len();
    let mut inline = [0.0; INLINE_CONTACTS];
    let e: &mut [f64] = if n <= INLINE_CONTACTS {
        &mut inline[..n]
    } else {
        heap.clear();
        heap.resize(n, 0.0);
        heap
    };
    for (slot, &a) in e.iter_mut().zip(ends) {
        *slot = mod_two_pi(a);
    }
    e.sort_unstable_by(f64::total_cmp);
    let step = TWO_PI / n as f64;
    for (j, v) in e.iter_mut().enumerate() {
        *v -= step * j as f64;
    }
    let mut best = f64::INFINITY;
    for &ek in e.iter() {
        let mut sum = 0.0;
        for &ej in e.iter() {
            let x = (ek - ej).abs();
            sum += x.min(TWO_PI - x);
        }
        best = best.min(sum);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lambda_of(degrees: &[f64]) -> f64 {
        let angles: Vec<f64> = degrees.iter().map(|d| d.to_radians()).collect();
        let owner = vec![0; angles.len()];
        stability_index(&owner, &angles, 1).unwrap().0[0]
    }

    #[test]
    fn reference_values() {
        assert!((lambda_of(&[0.0, 60.0, 120.0]) - 1.0 / 3.0).abs() < 1e-14);
        assert!((lambda_of(&[0.0, 90.0]) - 0.25).abs() < 1e-14);
        assert!(lambda_of(&[0.0, 180.0]).abs() < 1e-14);
        assert!(lambda_of(&[0.0, 60.0, 120.0, 180.0, 240.0, 300.0]).abs() < 1e-13);
        assert_eq!(lambda_of(&[]), 1.0);
        assert_eq!(lambda_of(&[42.0]), 1.0);
        // all n at one angle: floor(n^2/4)/n, here past the inline buffer
        let crowded = vec![10.0; 20];
        assert!((lambda_of(&crowded) - 5.0).abs() < 1e-12);
    }

    #[test]
    fn order_and_rotation_do_not_matter() {
        let a = lambda_of(&[10.0, 100.0, 250.0, 300.0]);
        let b = lambda_of(&[300.0, 10.0, 250.0, 100.0]);
        let c = lambda_of(&[10.0 + 720.0, 100.0 - 360.0, 250.0, 300.0]);
        let d = lambda_of(&[47.0, 137.0, 287.0, 337.0]);
        assert_eq!(a, b);
        assert!((a - c).abs() < 1e-13 && (a - d).abs() < 1e-13);
    }

    #[test]
    fn independent_of_thread_count() {
        let n = 3 * CHUNK + 17;
        let owner: Vec<usize> = (0..5 * n).map(|k| (k * 7919) % n).collect();
        let angles: Vec<f64> = (0..5 * n)
            .map(|k| (k as f64 * 0.618_034).sin() * 9.0)
            .collect();
        let one = crate::analysis::with_threads(1, || stability_index(&owner, &angles, n)).unwrap();
        let two = crate::analysis::with_threads(2, || stability_index(&owner, &angles, n)).unwrap();
        assert_eq!(one.unwrap(), two.unwrap());
    }

    #[test]
    fn contacts_give_the_ends_of_both_particles() {
        let ci = [0, 0, 1, 2];
        let cj = [1, 2, 3, 3];
        let angles = [0.1, 1.3, 5.9, 3.0];
        let mut owner = ci.to_vec();
        owner.extend_from_slice(&cj);
        let mut ends = angles.to_vec();
        ends.extend(angles.iter().map(|a| (a + std::f64::consts::PI) % TWO_PI));
        let from_contacts = stability_index_of_contacts(&ci, &cj, &angles, 5).unwrap();
        let from_ends = stability_index(&owner, &ends, 5).unwrap();
        assert_eq!(from_contacts.1, vec![2, 2, 2, 2, 0]);
        for (a, b) in from_contacts.0.iter().zip(&from_ends.0) {
            assert!((a - b).abs() < 1e-15);
        }
        assert!(stability_index_of_contacts(&ci, &cj, &[0.0, 1.0, 2.0, 7.0], 5).is_err());
    }

    #[test]
    fn bad_input_is_named() {
        assert!(stability_index(&[0, 3], &[0.0, 1.0], 3)
            .unwrap_err()
            .to_string()
            .starts_with("owner"));
        assert!(stability_index(&[0], &[f64::NAN], 1)
            .unwrap_err()
            .to_string()
            .starts_with("angles[0]"));
    }
}
