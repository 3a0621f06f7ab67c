//! The little parallel machinery the step needs: map a function over work
//! blocks on the simulation's own thread pool (or inline with one thread),
//! results returned in block order so reductions are deterministic.
use rayon::prelude::*;

/// Applies `f` to every item, in parallel on the current rayon pool when
/// `parallel` is set (the caller runs inside the simulation's pool, see
/// `Simulation::run`); the results come back in item order.
pub fn map_blocks<T, R, F>(parallel: bool, items: Vec<T>, f: F) -> Vec<R>
where
    T: Send,
    R: Send,
    F: Fn(T) -> R + Sync + Send,
{
    if parallel && items.len() > 1 {
        items.into_par_iter().with_max_len(1).map(f).collect()
    } else {
        items.into_iter().map(f).collect()
    }
}

/// A raw pointer that may be shared between threads that write *disjoint*
/// elements: each particle belongs to exactly one block, and a block's task
/// only writes forces of its own particles.
#[derive(Clone, Copy)]
pub struct DisjointWriter<T>(*mut T);

// SAFETY: users promise that concurrent tasks touch disjoint indices.
unsafe impl<T: Send> Send for DisjointWriter<T> {}
unsafe impl<T: Send> Sync for DisjointWriter<T> {}

impl<T> DisjointWriter<T> {
    /// Wraps a slice.
    pub fn new(slice: &mut [T]) -> Self {
        DisjointWriter(slice.as_mut_ptr())
    }

    /// Mutable access to element `k`.
    ///
    /// # Safety
    /// `k` must be in bounds of the wrapped slice, the slice must outlive the
    /// use, and no other task may access element `k` concurrently.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn get(&self, k: usize) -> &mut T {
        &mut *self.0.add(k)
    }
}

/// Splits `0..n` into `parts` contiguous ranges of near-equal length.
pub fn even_bounds(n: usize, parts: usize) -> Vec<(usize, usize)> {
    let parts = parts.max(1);
    (0..parts)
        .map(|b| (b * n / parts, (b + 1) * n / parts))
        .collect()
}

/// Splits a slice at the given contiguous ranges (which must tile it in order).
pub fn split_ranges<'a, T>(mut slice: &'a mut [T], ranges: &[(usize, usize)]) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(ranges.len());
    let mut consumed = 0;
    for &(lo, hi) in ranges {
        debug_assert_eq!(lo, consumed);
        let (head, tail) = std::mem::take(&mut slice).split_at_mut(hi - lo);
        out.push(head);
        slice = tail;
        consumed = hi;
    }
    out
}
