//! Fabric analysis kernels for large snapshots: contacts from geometry, the
//! stability index, rattlers, the contact-normal histogram, Fourier moment and
//! fabric tensor.
//!
//! These are the compiled counterparts of grainlab's NumPy analysis (the
//! formulas are in docs/fabric.md). They take plain slices, know nothing of
//! files or Python, and run on rayon's current pool: [`with_threads`] runs a
//! kernel on a pool of a given size.
//!
//! Every kernel splits its work into pieces of a fixed size ([`CHUNK`]
//! particles or contacts), whatever the number of threads, and merges the
//! pieces' results in piece order, so results are bitwise the same on any
//! number of threads.
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use rayon::ThreadPool;

use crate::error::{EngineError, Result};

pub mod contacts;
pub mod fabric;
pub mod stability;

pub use contacts::{contact_normals, detect_contacts, ContactPairs, PeriodicAxis};
pub use fabric::{angular_histogram, fabric_tensor, fourier_moment, rattlers, FourierMoment};
pub use stability::{stability_index, stability_index_of_contacts};

/// Particles or contacts per piece of parallel work (a fixed size, so that
/// the split, and every sum over pieces, does not depend on the thread count).
pub const CHUNK: usize = 1 << 14;

/// 2 pi.
pub(crate) const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// Runs `work` on a rayon pool of `threads` workers (kept for later calls);
/// `threads = 0` runs it on the current pool.
pub fn with_threads<T: Send>(threads: usize, work: impl FnOnce() -> T + Send) -> Result<T> {
    if threads == 0 {
        return Ok(work());
    }
    static POOLS: OnceLock<Mutex<HashMap<usize, Arc<ThreadPool>>>> = OnceLock::new();
    let pool = {
        let mut pools = POOLS
            .get_or_init(|| Mutex::new(HashMap::new()))
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        match pools.get(&threads) {
            Some(pool) => Arc::clone(pool),
            None => {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .thread_name(|k| format!("grainlab-analysis-{k}"))
                    .build()
                    .map_err(|e| EngineError::invalid("threads", e.to_string()))?;
                let pool = Arc::new(pool);
                pools.insert(threads, Arc::clone(&pool));
                pool
            }
        }
    };
    Ok(pool.install(work))
}

/// Checks that a per-item slice has `n` entries.
pub(crate) fn require_len(field: &str, len: usize, n: usize, of: &str) -> Result<()> {
    if len == n {
        Ok(())
    } else {
        Err(EngineError::invalid(
            field,
            format!("has {len} entries, expected {n} (one per {of})"),
        ))
    }
}

/// Checks that every index is below `n` (and not negative), naming the first
/// that is not and the item (`what`) it belongs to.
pub(crate) fn require_indices<T: Copy + TryInto<i64> + std::fmt::Display>(
    field: &str,
    values: &[T],
    n: usize,
    what: &str,
) -> Result<()> {
    let bound = n as i64;
    match values.iter().position(|&v| {
        let v: Option<i64> = v.try_into().ok();
        v.is_none_or(|v| v < 0 || v >= bound)
    }) {
        None => Ok(()),
        Some(k) => Err(EngineError::invalid(
            field,
            format!("index {} out of range [0, {n}) at {what} {k}", values[k]),
        )),
    }
}

/// Checks that every value is finite, naming the first one that is not.
pub(crate) fn require_all_finite(field: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(k) => Err(EngineError::invalid(
            format!("{field}[{k}]"),
            format!("must be finite, got {}", values[k]),
        )),
    }
}

/// `x mod 2 pi` in `[0, 2 pi]` with the sign of the divisor, as NumPy's `mod`
/// computes it (a tiny negative `x` rounds up to exactly 2 pi).
#[inline]
pub(crate) fn mod_two_pi(x: f64) -> f64 {
    if (0.0..TWO_PI).contains(&x) {
        return x;
    }
    let r = x % TWO_PI;
    if r < 0.0 {
        r + TWO_PI
    } else {
        r
    }
}
