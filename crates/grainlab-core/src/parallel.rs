//! The little parallel machinery the step needs.
//!
//! A DEM step has two short parallel phases (contact forces per stripe,
//! integration per stripe) separated by short sequential work, thousands of
//! times per second. Handing each phase to a thread pool costs a wake-up per
//! phase, as long as the phase itself on a 2-core machine. So `Simulation::run`
//! enters its rayon pool *once* per call with a broadcast: worker 0 runs the
//! step loop, the other workers wait for phases in a [`Team`], spinning, and
//! each phase is handed to them with one atomic store. Results of a phase come
//! back in stripe order, so every reduction is deterministic.
//!
//! On a shared machine a worker may not be running when a phase starts. A
//! phase therefore never waits for a worker that has not joined it: worker 0
//! takes every item nobody else took, and waits only for workers that are in
//! the middle of an item. When the team still loses time (a worker descheduled
//! in the middle of its items), a [`Pacer`] times the steps with and without
//! the team and runs them on worker 0 alone while that is faster; which thread
//! runs what never changes a result.
use std::cell::UnsafeCell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use std::thread::Thread;
use std::time::{Duration, Instant};

/// A waiting thread spins for `SPIN` (the hand-over of a phase is then a
/// cache-line transfer), then yields its core between checks until `YIELD`
/// (on a shared machine the thread it waits for may need that core), then
/// parks until woken. A wake-up from a park costs as much as a phase, so the
/// first two stages cover the ordinary waits of a step.
const SPIN: Duration = Duration::from_micros(200);
const YIELD: Duration = Duration::from_millis(2);

type Job = dyn Fn(usize) + Sync;

/// The gate word's flag: the current phase accepts workers.
const OPEN: u64 = 1 << 31;
/// The gate word's low bits: workers inside the current phase.
const INSIDE: u64 = OPEN - 1;

/// Workers of one `run` call, waiting for phases from worker 0.
pub struct Team {
    size: usize,
    /// `(phase << 32) | OPEN? | workers inside`: a worker joins a phase by a
    /// compare-exchange that succeeds only while it is open, so once worker 0
    /// closed it no worker can start reading its job.
    gate: CacheLine<AtomicU64>,
    quit: AtomicBool,
    panicked: AtomicBool,
    job: UnsafeCell<Option<*const Job>>,
    leader: OnceLock<Thread>,
    workers: Mutex<Vec<Thread>>,
}

// SAFETY: `job` is written only by worker 0 while the gate is closed and no
// worker is inside a phase, and read only by workers that joined the open phase.
unsafe impl Sync for Team {}

impl Team {
    /// A team of `size` workers (worker 0 included).
    pub fn new(size: usize) -> Self {
        Team {
            size,
            gate: CacheLine(AtomicU64::new(0)),
            quit: AtomicBool::new(false),
            panicked: AtomicBool::new(false),
            job: UnsafeCell::new(None),
            leader: OnceLock::new(),
            workers: Mutex::new(Vec::new()),
        }
    }

    /// Number of workers.
    pub fn size(&self) -> usize {
        self.size
    }

    /// Runs `job(k)` on worker 0 (the caller) and on every worker `k` that
    /// joins before worker 0's own `job(0)` returns, and waits for those. The
    /// job must hand out its work so that `job(0)` returns only once all of it
    /// is taken ([`map_stripes`] does): a worker that is not running is then
    /// neither needed nor waited for.
    pub fn run<'a>(&self, job: &'a (dyn Fn(usize) + Sync + 'a)) {
        self.leader.get_or_init(std::thread::current);
        // SAFETY: the lifetime is erased only until this function returns, and it
        // returns after every worker that joined finished with the job; no worker
        // can join after the gate is closed below.
        let erased: *const Job =
            unsafe { std::mem::transmute::<&'a (dyn Fn(usize) + Sync + 'a), &'static Job>(job) };
        unsafe { *self.job.get() = Some(erased) };
        let gate = &self.gate.0;
        // phases count from 1 (0 is "none served yet" for the workers)
        let phase = ((gate.load(Ordering::Relaxed) >> 32) % 0xffff_ffff) + 1;
        gate.store((phase << 32) | OPEN, Ordering::Release);
        self.wake_workers();
        job(0);
        gate.fetch_and(!OPEN, Ordering::AcqRel);
        wait_until(|| gate.load(Ordering::Acquire) & INSIDE == 0);
        if self.panicked.load(Ordering::Acquire) {
            panic!("a grainlab worker thread panicked");
        }
    }

    /// Worker `index` (>= 1) serves phases until [`Team::dismiss`].
    pub fn serve(&self, index: usize) {
        self.workers
            .lock()
            .expect("worker list")
            .push(std::thread::current());
        let gate = &self.gate.0;
        let mut served = 0u64;
        loop {
            let mut word = 0;
            wait_until(|| {
                word = gate.load(Ordering::Acquire);
                (word & OPEN != 0 && word >> 32 != served) || self.quit.load(Ordering::Acquire)
            });
            if word & OPEN == 0 || word >> 32 == served {
                return; // dismissed
            }
            if gate
                .compare_exchange(word, word + 1, Ordering::AcqRel, Ordering::Acquire)
                .is_err()
            {
                continue; // closed meanwhile, or another worker joined first: look again
            }
            served = word >> 32;
            // SAFETY: published before the phase was opened, and the phase cannot
            // end while this worker is inside it.
            let job = unsafe { (*self.job.get()).expect("a job with the phase") };
            if catch_unwind(AssertUnwindSafe(|| unsafe { (*job)(index) })).is_err() {
                self.panicked.store(true, Ordering::Release);
            }
            let before = gate.fetch_sub(1, Ordering::AcqRel);
            if before & INSIDE == 1 && before & OPEN == 0 {
                if let Some(leader) = self.leader.get() {
                    leader.unpark();
                }
            }
        }
    }

    /// Lets the serving workers return.
    pub fn dismiss(&self) {
        self.quit.store(true, Ordering::Release);
        self.wake_workers();
    }

    fn wake_workers(&self) {
        for worker in self.workers.lock().expect("worker list").iter() {
            worker.unpark();
        }
    }
}

/// Waits for `ready`: spins, then yields, then parks between checks (an
/// `unpark` from the thread that makes it true, or a short timeout, ends each park).
#[inline]
fn wait_until(mut ready: impl FnMut() -> bool) {
    if ready() {
        return;
    }
    let start = Instant::now();
    let mut spins = 0u32;
    while !ready() {
        spins += 1;
        if spins % 64 != 0 {
            std::hint::spin_loop();
            continue;
        }
        let waited = start.elapsed();
        if waited < SPIN {
            std::hint::spin_loop();
        } else if waited < YIELD {
            std::thread::yield_now();
        } else {
            std::thread::park_timeout(Duration::from_micros(200));
        }
    }
}

/// Steps timed per window of the [`Pacer`].
const PACER_WINDOW: u32 = 32;
/// Windows between two tries of the mode not in use, at first and at most.
const PACER_FIRST_TRY: u32 = 4;
const PACER_LAST_TRY: u32 = 256;

/// Decides, window by window, whether the steps run with the team or on
/// worker 0 alone: whichever took less time per step when last timed. The mode
/// in use is timed every window; the other one is tried for a window now and
/// then, less often each time the try confirms the choice, so that a team
/// that helps costs almost nothing to keep and a busy core is noticed within
/// a window. Windows with a neighbour rebuild are not counted (a rebuild costs
/// as much as many steps). Results do not depend on the mode.
#[derive(Debug, Clone)]
pub struct Pacer {
    alone: bool,
    trying: bool,
    /// Latest seconds per step with the team (`[0]`) and alone (`[1]`).
    per_step: [Option<f64>; 2],
    steps: u32,
    clean: bool,
    start: Option<Instant>,
    windows: u32,
    try_every: u32,
}

impl Default for Pacer {
    fn default() -> Self {
        Pacer {
            alone: false,
            trying: false,
            per_step: [None, None],
            steps: 0,
            clean: true,
            start: None,
            windows: 0,
            try_every: PACER_FIRST_TRY,
        }
    }
}

impl Pacer {
    /// Whether the next step runs on worker 0 alone.
    pub fn alone(&self) -> bool {
        self.alone
    }

    /// Starts timing (at the start of a `run` call: time between calls is not
    /// the steps').
    pub fn start(&mut self) {
        self.steps = 0;
        self.clean = true;
        self.start = Some(Instant::now());
    }

    /// Counts a step (`rebuilt`: it rebuilt the neighbour lists) and, at the
    /// end of a window, chooses the mode of the next one.
    pub fn step_done(&mut self, rebuilt: bool) {
        self.clean &= !rebuilt;
        self.steps += 1;
        if self.steps < PACER_WINDOW {
            return;
        }
        let now = Instant::now();
        let mode = self.alone as usize;
        if let (true, Some(start)) = (self.clean, self.start) {
            let t = (now - start).as_secs_f64() / self.steps as f64;
            self.choose(mode, t);
        }
        self.steps = 0;
        self.clean = true;
        self.start = Some(now);
    }

    /// Takes `t` seconds per step in `mode` (0 team, 1 alone) and sets the next mode.
    fn choose(&mut self, mode: usize, t: f64) {
        self.per_step[mode] = Some(t);
        let other = 1 - mode;
        let better_other = self.per_step[other].is_some_and(|o| o < t);
        if self.trying {
            // the window just timed tried `mode`
            self.trying = false;
            if better_other {
                self.alone = other == 1;
                self.try_every = (2 * self.try_every).min(PACER_LAST_TRY);
            } else {
                self.try_every = PACER_FIRST_TRY;
            }
            self.windows = 0;
        } else if better_other {
            self.alone = other == 1;
            self.try_every = PACER_FIRST_TRY;
            self.windows = 0;
        } else {
            self.windows += 1;
            if self.windows >= self.try_every {
                self.trying = true;
                self.alone = other == 1;
                self.windows = 0;
            }
        }
    }
}

/// Applies `f` to every item; with a team, each worker first runs the items
/// of its own home share (the same share in every phase and every step, so a
/// worker keeps finding its particles in its own cache), then helps the others
/// by taking items from the far end of their shares (so a slow core does not
/// hold the step up). Without a team the items run in order on this thread.
/// Results come back in item order either way, so every reduction over them is
/// deterministic whichever worker ran what.
pub fn map_stripes<T, R, F>(team: Option<&Team>, items: Vec<T>, f: F) -> Vec<R>
where
    T: Send,
    R: Send,
    F: Fn(T) -> R + Sync,
{
    match team {
        Some(team) if items.len() > 1 => {
            let slots: Vec<ClaimSlot<T, R>> = items.into_iter().map(ClaimSlot::new).collect();
            let shares = HomeShares::new(slots.len(), team.size());
            team.run(&|worker| {
                while let Some(k) = shares.claim(worker) {
                    // SAFETY: `claim` hands each index to exactly one worker
                    unsafe { slots[k].run(&f) };
                }
            });
            // `team.run` returned: every worker is done with the slots
            slots.into_iter().map(ClaimSlot::into_result).collect()
        }
        _ => items.into_iter().map(f).collect(),
    }
}

/// The items of a phase shared out in contiguous home ranges, one per worker.
/// Each range is one atomic word `(front << 32) | back`: the owner takes items
/// from the front, the others take them from the back, and a compare-exchange
/// makes sure every item is taken exactly once.
struct HomeShares {
    ranges: Vec<CacheLine<AtomicU64>>,
}

/// Keeps a value on a cache line (pair of lines, for the adjacent-line
/// prefetcher) of its own, so that workers claiming from their own shares do
/// not take the line from each other.
#[repr(align(128))]
struct CacheLine<T>(T);

impl HomeShares {
    fn new(items: usize, workers: usize) -> Self {
        let workers = workers.max(1);
        let ranges = (0..workers)
            .map(|w| {
                let (lo, hi) = (w * items / workers, (w + 1) * items / workers);
                CacheLine(AtomicU64::new(((lo as u64) << 32) | hi as u64))
            })
            .collect();
        HomeShares { ranges }
    }

    /// The next item for `worker`: its own next one, or else one from the end
    /// of another worker's share; `None` once every item is taken.
    fn claim(&self, worker: usize) -> Option<usize> {
        let n = self.ranges.len();
        let own = worker % n;
        if let Some(k) = self.take(own, true) {
            return Some(k);
        }
        (1..n).find_map(|v| self.take((own + v) % n, false))
    }

    fn take(&self, share: usize, from_front: bool) -> Option<usize> {
        let word = &self.ranges[share].0;
        let mut current = word.load(Ordering::Acquire);
        loop {
            let (front, back) = (current >> 32, current & 0xffff_ffff);
            if front >= back {
                return None;
            }
            let (next, item) = if from_front {
                (((front + 1) << 32) | back, front)
            } else {
                ((front << 32) | (back - 1), back - 1)
            };
            match word.compare_exchange_weak(current, next, Ordering::AcqRel, Ordering::Acquire) {
                Ok(_) => return Some(item as usize),
                Err(seen) => current = seen,
            }
        }
    }
}

/// An item and, once it has run, its result; each is claimed by exactly one
/// worker (through an atomic counter), so it needs no lock.
struct ClaimSlot<T, R> {
    item: UnsafeCell<Option<T>>,
    result: UnsafeCell<Option<R>>,
}

// SAFETY: a slot is touched by one worker at a time (see `map_stripes`).
unsafe impl<T: Send, R: Send> Sync for ClaimSlot<T, R> {}

impl<T, R> ClaimSlot<T, R> {
    fn new(item: T) -> Self {
        ClaimSlot {
            item: UnsafeCell::new(Some(item)),
            result: UnsafeCell::new(None),
        }
    }

    /// # Safety
    /// Only the worker that claimed this slot may call it, once.
    unsafe fn run(&self, f: &impl Fn(T) -> R) {
        let item = (*self.item.get()).take().expect("each item claimed once");
        *self.result.get() = Some(f(item));
    }

    fn into_result(self) -> R {
        self.result.into_inner().expect("every item ran")
    }
}

/// Below this many particles a system is one stripe, run on the calling
/// thread: the hand-over of a phase would cost more than it saves.
pub const PARALLEL_MIN_PARTICLES: usize = 3000;

/// Particles per work stripe: enough stripes for a few per worker (which then
/// balance their load by claiming stripes), few enough that the pairs across
/// stripes, buffered and applied afterwards, stay a small part of all pairs.
pub const PARTICLES_PER_STRIPE: usize = 500;

/// Bin columns per stripe at least: a narrower stripe has most pairs across.
pub const MIN_COLUMNS_PER_STRIPE: usize = 3;

/// Most stripes of a system (four per worker on four cores).
pub const MAX_STRIPES: usize = 16;

/// Number of work stripes for `particles` disks in `columns` bin columns.
///
/// It depends on the system only, never on the thread count: every thread count
/// runs the same partition, the same pairs in the same order and the same
/// reductions in stripe order, so results are bitwise independent of it.
pub fn stripe_count(particles: usize, columns: usize) -> usize {
    if particles < PARALLEL_MIN_PARTICLES {
        return 1;
    }
    (particles / PARTICLES_PER_STRIPE)
        .min(columns / MIN_COLUMNS_PER_STRIPE)
        .clamp(1, MAX_STRIPES)
}
/// A raw pointer that may be shared between threads that write *disjoint*
/// elements: each particle belongs to exactly one stripe, and a stripe's task
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

    /// Mutable access to elements `lo..hi`.
    ///
    /// # Safety
    /// As [`DisjointWriter::get`], for every element of the range.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn range(&self, lo: usize, hi: usize) -> &mut [T] {
        std::slice::from_raw_parts_mut(self.0.add(lo), hi - lo)
    }
}

/// Items grouped by the stripe of particles each belongs to, in their given
/// order within a stripe (CSR: stripe `b`'s are `entries[start[b]..start[b + 1]]`),
/// so that each stripe can work through its own items in the order a pass over
/// all of them would.
#[derive(Debug, Clone)]
pub(crate) struct StripeLists<T> {
    entries: Vec<T>,
    start: Vec<usize>,
}

impl<T> Default for StripeLists<T> {
    fn default() -> Self {
        StripeLists {
            entries: Vec::new(),
            start: Vec::new(),
        }
    }
}

impl<T: Clone> StripeLists<T> {
    /// `(particle, item)` pairs, in order, grouped by the stripe of `stripe_ranges`
    /// (contiguous, in order) that holds the particle; `None` when a particle
    /// lies outside them (stripes of an older list).
    pub(crate) fn new(
        stripe_ranges: &[(usize, usize)],
        items: impl Iterator<Item = (usize, T)>,
    ) -> Option<Self> {
        let mut per_stripe: Vec<Vec<T>> = vec![Vec::new(); stripe_ranges.len()];
        for (q, item) in items {
            let b = stripe_ranges.partition_point(|&(_, hi)| hi <= q);
            if b >= stripe_ranges.len() || q < stripe_ranges[b].0 {
                return None;
            }
            per_stripe[b].push(item);
        }
        let mut start = Vec::with_capacity(stripe_ranges.len() + 1);
        start.push(0);
        let mut entries = Vec::new();
        for list in per_stripe {
            entries.extend(list);
            start.push(entries.len());
        }
        Some(StripeLists { entries, start })
    }
}

impl<T> StripeLists<T> {
    /// Stripe `b`'s items (none when the lists were never built).
    pub(crate) fn of_stripe(&self, b: usize) -> &[T] {
        match (self.start.get(b), self.start.get(b + 1)) {
            (Some(&lo), Some(&hi)) => &self.entries[lo..hi],
            _ => &[],
        }
    }

    /// The number of stripes the lists were built for (0 when never built).
    pub(crate) fn n_stripes(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// The number of items over every stripe.
    pub(crate) fn len(&self) -> usize {
        self.entries.len()
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU32;

    #[test]
    fn home_shares_start_with_each_workers_own_range() {
        let shares = HomeShares::new(8, 2);
        assert_eq!(shares.claim(0), Some(0));
        assert_eq!(shares.claim(1), Some(4));
        assert_eq!(shares.claim(0), Some(1));
        // worker 1 drains its own share front to back ...
        assert_eq!(shares.claim(1), Some(5));
        assert_eq!(shares.claim(1), Some(6));
        assert_eq!(shares.claim(1), Some(7));
        // ... then takes from the far end of worker 0's share
        assert_eq!(shares.claim(1), Some(3));
        assert_eq!(shares.claim(0), Some(2));
        assert_eq!(shares.claim(0), None);
        assert_eq!(shares.claim(1), None);
    }

    #[test]
    fn every_item_is_claimed_exactly_once_under_contention() {
        for (items, workers) in [(8, 2), (13, 3), (1, 4), (64, 4)] {
            for _ in 0..200 {
                let shares = HomeShares::new(items, workers);
                let hits: Vec<AtomicU32> = (0..items).map(|_| AtomicU32::new(0)).collect();
                std::thread::scope(|s| {
                    for w in 0..workers {
                        let (shares, hits) = (&shares, &hits);
                        s.spawn(move || {
                            while let Some(k) = shares.claim(w) {
                                hits[k].fetch_add(1, Ordering::Relaxed);
                            }
                        });
                    }
                });
                assert!(hits.iter().all(|h| h.load(Ordering::Relaxed) == 1));
            }
        }
    }

    #[test]
    fn map_stripes_returns_results_in_item_order_with_a_team() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let team = Team::new(2);
        let out = pool.broadcast(|ctx| {
            if ctx.index() == 0 {
                let r = map_stripes(Some(&team), (0..37u64).collect(), |k| k * k);
                team.dismiss();
                Some(r)
            } else {
                team.serve(ctx.index());
                None
            }
        });
        let squares = out.into_iter().next().flatten().unwrap();
        assert_eq!(squares, (0..37u64).map(|k| k * k).collect::<Vec<_>>());
    }
}
