//! Where a case's time and memory go: wall seconds by phase of the solve (weights,
//! constitutive update, tangent assembly, linear set-up, linear solve) and the heap it held at
//! its peak, accounted per case even when several cases run at once.
//!
//! Accounting is by *slot*: a case runs on threads tagged with its slot
//! ([`CasePool`]: a rayon pool whose threads carry the tag, one case at a time), the solver
//! charges each phase's wall time to the slot of the thread that ran it ([`charge`]), and the
//! [`CountingAllocator`] — when a binary installs it as its global allocator — adds every
//! allocation and release of a tagged thread to that slot's live bytes and high-water mark.
//! Untagged threads (a library user's, a unit test's) charge slot 0, which nobody reads.
//!
//! Times are wall-clock and vary from run to run (and with the cases that share the cores);
//! they go to `results.json`'s `timing` block only, never into a case's record.

use serde::{Deserialize, Serialize};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicI64, AtomicU64, AtomicUsize, Ordering::Relaxed};
use std::time::Instant;

/// A phase of a solve whose wall time is accounted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Supports and weights (GIMP/MPM, eqs 7–10) or shape functions, and the ghost faces.
    Weights = 0,
    /// Point updates: ΔF, log strain, stress return and the internal force (eqs 14–19, 28).
    Constitutive = 1,
    /// Tangent assembly (eq 27), ghost penalty included.
    Assembly = 2,
    /// Dof map and sparsity pattern, symbolic and numeric factorisation, multigrid set-up.
    Setup = 3,
    /// Triangular solves or Krylov iterations.
    Solve = 4,
}

const PHASES: usize = 5;
/// Slots in the table; slot 0 is the untagged threads'. Pools take slots round-robin, so a
/// slot is reused only this many pools later (more than ever run at once).
const SLOTS: usize = 256;

struct Slot {
    nanos: [AtomicU64; PHASES],
    live: AtomicI64,
    peak: AtomicI64,
}

impl Slot {
    const fn new() -> Self {
        Slot {
            nanos: [const { AtomicU64::new(0) }; PHASES],
            live: AtomicI64::new(0),
            peak: AtomicI64::new(0),
        }
    }

    fn reset(&self) {
        for n in &self.nanos {
            n.store(0, Relaxed);
        }
        self.live.store(0, Relaxed);
        self.peak.store(0, Relaxed);
    }
}

static TABLE: [Slot; SLOTS] = [const { Slot::new() }; SLOTS];
static NEXT_SLOT: AtomicUsize = AtomicUsize::new(0);
/// Set by the first allocation through [`CountingAllocator`]: heap figures are real.
static COUNTING: AtomicBool = AtomicBool::new(false);

thread_local! {
    // A const-initialised `Cell<usize>` has no destructor, so the allocator may read it at
    // any point of a thread's life, teardown included.
    static CURRENT: Cell<usize> = const { Cell::new(0) };
}

fn current_slot() -> usize {
    CURRENT.with(Cell::get)
}

/// Add the wall time since `start` to `phase` of the current thread's case; returns it in
/// seconds.
pub fn charge(phase: Phase, start: Instant) -> f64 {
    let elapsed = start.elapsed();
    let nanos = u64::try_from(elapsed.as_nanos()).unwrap_or(u64::MAX);
    TABLE[current_slot()].nanos[phase as usize].fetch_add(nanos, Relaxed);
    elapsed.as_secs_f64()
}

/// Run `f` and charge its wall time to `phase`.
pub fn timed<R>(phase: Phase, f: impl FnOnce() -> R) -> R {
    let start = Instant::now();
    let r = f();
    charge(phase, start);
    r
}

/// What one case cost: wall seconds in total and by phase, and its heap peak.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct CaseCost {
    /// Wall seconds of the whole case (solve, records, side files).
    pub seconds: f64,
    /// Seconds in supports and weights or shape functions ([`Phase::Weights`]).
    pub weights: f64,
    /// Seconds in point updates and the internal force ([`Phase::Constitutive`]).
    pub constitutive: f64,
    /// Seconds in tangent assembly ([`Phase::Assembly`]).
    pub assembly: f64,
    /// Pattern, factorisation or multigrid set-up.
    pub setup: f64,
    /// Seconds in triangular solves or Krylov iterations ([`Phase::Solve`]).
    pub solve: f64,
    /// Most heap bytes the case held at once, above what it started with (absent when the
    /// binary does not count allocations).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heap_peak_bytes: Option<u64>,
}

impl CaseCost {
    /// Seconds outside the accounted phases (load stepping, commits, domain update, output).
    pub fn other(&self) -> f64 {
        (self.seconds - self.weights - self.constitutive - self.assembly - self.setup - self.solve).max(0.0)
    }

    fn of_slot(slot: usize, seconds: f64) -> Self {
        let s = &TABLE[slot];
        let secs = |p: Phase| s.nanos[p as usize].load(Relaxed) as f64 * 1e-9;
        CaseCost {
            seconds,
            weights: secs(Phase::Weights),
            constitutive: secs(Phase::Constitutive),
            assembly: secs(Phase::Assembly),
            setup: secs(Phase::Setup),
            solve: secs(Phase::Solve),
            heap_peak_bytes: COUNTING
                .load(Relaxed)
                .then(|| u64::try_from(s.peak.load(Relaxed)).unwrap_or(0)),
        }
    }
}

/// What the current thread's case has cost so far, with `seconds` 0.
pub fn current() -> CaseCost {
    CaseCost::of_slot(current_slot(), 0.0)
}

/// A rayon pool whose threads carry a slot of their own: cases run on it one after another
/// ([`CasePool::run`]) are accounted one by one, and nested parallel work stays on the pool,
/// so a case's phases and allocations are its own even while other pools run other cases.
/// The engine keeps one per case it runs at once, so that threads (and their allocator
/// arenas) are reused from case to case.
pub struct CasePool {
    pool: Option<rayon::ThreadPool>,
    slot: usize,
}

impl CasePool {
    /// A pool of `threads` threads on a fresh slot.
    pub fn new(threads: usize) -> Self {
        let slot = 1 + NEXT_SLOT.fetch_add(1, Relaxed) % (SLOTS - 1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .start_handler(move |_| CURRENT.with(|c| c.set(slot)))
            .build()
            .ok();
        CasePool { pool, slot }
    }

    /// Run `f` as one case and return its result with what it cost (accounting starts from
    /// zero).
    pub fn run<R: Send>(&self, f: impl FnOnce() -> R + Send) -> (R, CaseCost) {
        TABLE[self.slot].reset();
        let start = Instant::now();
        let r = match &self.pool {
            Some(pool) => pool.install(f),
            // No threads to be had: run on this one, tagged for the duration.
            None => {
                let outer = CURRENT.with(|c| c.replace(self.slot));
                let r = f();
                CURRENT.with(|c| c.set(outer));
                r
            }
        };
        (r, CaseCost::of_slot(self.slot, start.elapsed().as_secs_f64()))
    }
}

/// Reset this process's peak resident memory to its current size (Linux: `5` written to
/// `/proc/self/clear_refs`), so that [`peak_resident_bytes`] measures from here; `false` if
/// the system does not allow it.
pub fn reset_peak_resident() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Peak resident memory of this process (Linux `VmHWM`), if the system reports it.
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The system allocator, counting each tagged thread's live heap bytes and their peak into its
/// case's slot. Install it in a binary to have heap peaks in [`CaseCost`]:
///
/// ```ignore
/// #[global_allocator]
/// static ALLOCATOR: igimp::solver::profile::CountingAllocator = igimp::solver::profile::CountingAllocator;
/// ```
pub struct CountingAllocator;

fn count(delta: i64) {
    let slot = &TABLE[current_slot()];
    let live = slot.live.fetch_add(delta, Relaxed) + delta;
    if delta > 0 {
        slot.peak.fetch_max(live, Relaxed);
    }
}

fn mark_counting() {
    if !COUNTING.load(Relaxed) {
        COUNTING.store(true, Relaxed);
    }
}

// SAFETY: every call is forwarded to `System` with the caller's arguments; the counting
// touches only atomics and a destructor-free thread local, and never allocates.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        if !p.is_null() {
            mark_counting();
            count(layout.size() as i64);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(layout);
        if !p.is_null() {
            mark_counting();
            count(layout.size() as i64);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout);
        count(-(layout.size() as i64));
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = System.realloc(ptr, layout, new_size);
        if !p.is_null() {
            count(new_size as i64 - layout.size() as i64);
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phases_charge_the_case_that_ran_them() {
        let pool = CasePool::new(2);
        let (_, a) = pool.run(|| {
            timed(Phase::Assembly, || {
                std::thread::sleep(std::time::Duration::from_millis(20))
            });
            // Nested parallel work runs on the case's pool, under its slot.
            rayon::join(
                || {
                    charge(
                        Phase::Solve,
                        Instant::now() - std::time::Duration::from_millis(30),
                    )
                },
                || (),
            );
        });
        assert!(a.assembly >= 0.02 && a.assembly < 1.0, "{a:?}");
        assert!(a.solve >= 0.03 && a.solve < 1.0, "{a:?}");
        assert_eq!(a.weights, 0.0);
        assert!(a.seconds >= a.assembly);
        let (_, b) = pool.run(|| ());
        assert_eq!(b.assembly, 0.0, "the pool's next case starts from zero");
    }
}
