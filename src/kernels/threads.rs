//! The threads of a run (feature `parallel`): per-grain loops and the contact stage.
//!
//! [`Threads::split`] hands each thread one contiguous index range of the grains and
//! the matching parts of their arrays; thread r always gets range r, so its grains stay
//! in its cache from stage to stage. A per-grain loop sums nothing across grains, so its
//! bits do not depend on the number of threads. Without the feature (or with one thread)
//! the loop runs once over everything, with no overhead.
//!
//! A step hands work to the threads several times (each per-grain stage and the contact
//! stage), each for some tens of microseconds. rayon's pool puts idle workers to
//! sleep and wakes them through the kernel, which cost about as much as the work itself
//! here (measured: 1.16x on two cores at 20 000 grains). So the pool is a small
//! fork-join of its own: the calling thread is thread 0, the others spin on an epoch
//! counter for about a millisecond before they park, and a hand-over costs well under a
//! microsecond while the run is stepping.

/// What `grainlab handover` reports: a hand-over's time with no work, ns.
#[derive(Debug, serde::Serialize)]
pub struct HandOver {
    pub threads: usize,
    pub samples: usize,
    pub p10_ns: f64,
    pub median_ns: f64,
    pub p90_ns: f64,
}

/// [`Threads::hand_over_ns`] on a pool of `threads` (at least 2; feature `parallel`),
/// `samples` times (at least 1), summarised.
pub fn hand_over_summary(threads: usize, samples: usize) -> Result<HandOver, crate::error::Error> {
    Threads::check_count(threads, 2)?;
    if samples == 0 {
        return Err(crate::error::Error::BadOption { option: "--samples".into(), value: "0".into(), allowed: ">= 1".into() });
    }
    let pool = Threads::new(threads)?;
    let mut t = pool.hand_over_ns(samples);
    t.sort_by(f64::total_cmp);
    let at = |q: f64| t[((t.len() - 1) as f64 * q).round() as usize];
    Ok(HandOver { threads, samples, p10_ns: at(0.1), median_ns: at(0.5), p90_ns: at(0.9) })
}

/// Arrays (or tuples of them) that split at an index into two disjoint parts.
pub trait Split: Sized + Send {
    fn split_at(self, mid: usize) -> (Self, Self);
}

impl<T: Send> Split for &mut [T] {
    fn split_at(self, mid: usize) -> (Self, Self) {
        self.split_at_mut(mid)
    }
}

impl<T: Sync> Split for &[T] {
    fn split_at(self, mid: usize) -> (Self, Self) {
        <[T]>::split_at(self, mid)
    }
}

macro_rules! split_tuple {
    ($($t:ident $v:ident $a:ident $b:ident),+) => {
        impl<$($t: Split),+> Split for ($($t,)+) {
            fn split_at(self, mid: usize) -> (Self, Self) {
                let ($($v,)+) = self;
                $(let ($a, $b) = $v.split_at(mid);)+
                (($($a,)+), ($($b,)+))
            }
        }
    };
}
split_tuple!(A a a0 a1, B b b0 b1);
split_tuple!(A a a0 a1, B b b0 b1, C c c0 c1);
split_tuple!(A a a0 a1, B b b0 b1, C c c0 c1, D d d0 d1);
split_tuple!(A a a0 a1, B b b0 b1, C c c0 c1, D d d0 d1, E e e0 e1);

/// The threads a run may use.
#[derive(Clone, Default)]
pub struct Threads {
    #[cfg(feature = "parallel")]
    pool: Option<std::sync::Arc<pool::SpinPool>>,
}

/// Fewer grains per thread than this run on the calling thread: the hand-over costs more.
#[cfg(feature = "parallel")]
const MIN_PER_THREAD: usize = 1024;

impl Threads {
    /// The calling thread only.
    pub fn serial() -> Self {
        Threads::default()
    }

    /// A requested number of threads `n` (the `--threads` option) against what this build
    /// allows: at least `min`, and more than one only with the `parallel` feature.
    pub fn check_count(n: usize, min: usize) -> Result<(), crate::error::Error> {
        let invalid = |allowed: String| Err(crate::error::Error::BadOption { option: "--threads".into(), value: n.to_string(), allowed });
        if n > 1 && !cfg!(feature = "parallel") {
            let only = if min <= 1 { "1" } else { "none" };
            return invalid(format!("{only} (this build has no `parallel` feature: cargo build --release --features parallel)"));
        }
        if n < min {
            return invalid(format!(">= {min}"));
        }
        Ok(())
    }

    /// The calling thread and `n - 1` more (one thread: none); `n` as [`Threads::check_count`]
    /// allows with a minimum of 1.
    pub fn new(n: usize) -> Result<Self, crate::error::Error> {
        Threads::check_count(n, 1)?;
        #[cfg(feature = "parallel")]
        if n > 1 {
            let pool = pool::SpinPool::new(n).map_err(|e| crate::error::Error::Other(format!("starting {n} threads: {e}")))?;
            return Ok(Threads { pool: Some(std::sync::Arc::new(pool)) });
        }
        Ok(Threads::serial())
    }

    /// Number of threads.
    pub fn count(&self) -> usize {
        #[cfg(feature = "parallel")]
        if let Some(p) = &self.pool {
            return p.threads();
        }
        1
    }

    /// `f(part)` on one contiguous part of `0..n` per thread (`part` holds the arrays
    /// of all `n` grains). Thread r always gets part r, [r n / t, (r + 1) n / t), the
    /// grains it also owns in the contact stage.
    pub fn split<P: Split>(&self, n: usize, part: P, f: impl Fn(P) + Sync) {
        #[cfg(feature = "parallel")]
        if self.pool.is_some() && n >= MIN_PER_THREAD * self.count() {
            self.split_at_bounds(&self.bounds(n), part, |_, p| f(p));
            return;
        }
        let _ = n;
        f(part)
    }

    /// `f(range, part)` on one part of `0..n` per thread, as [`Threads::split`] shares them
    /// but with the last thread taking all grains from `n_free` on (the rough walls'
    /// grains, which follow their walls there); `range` is the part's place in
    /// `0..n`. The arrays of `part` may stop short of `n`
    /// (those of the free grains only): the last part has what is left of them.
    pub fn split_free<P: Split>(&self, n_free: usize, n: usize, part: P, f: impl Fn(std::ops::Range<usize>, P) + Sync) {
        #[cfg(feature = "parallel")]
        if self.pool.is_some() && n_free >= MIN_PER_THREAD * self.count() {
            // Equal shares of all grains: a glued grain cost the drift as much as a free
            // one (timed per thread at 20 000 grains, 2 x 800 glued: with equal shares of
            // the free grains the last thread ended 11-28 us after the first, with equal
            // shares of all 0.5-2 us, about its later start).
            let mut bounds = self.bounds(n);
            let t = self.count();
            bounds[..t].iter_mut().for_each(|b| *b = (*b).min(n_free));
            self.split_at_bounds(&bounds, part, f);
            return;
        }
        let _ = n_free;
        f(0..n, part)
    }

    /// `f(range, part)` on thread r for the part of the grains `range` = `bounds[r]..
    /// bounds[r + 1]` (one part per thread); the last part has what is left of the arrays.
    #[cfg(feature = "parallel")]
    fn split_at_bounds<P: Split>(&self, bounds: &[usize], part: P, f: impl Fn(std::ops::Range<usize>, P) + Sync) {
        let last = bounds.len() - 2;
        let mut parts = Vec::with_capacity(last + 1);
        let mut rest = Some(part);
        for (r, w) in bounds.windows(2).enumerate() {
            let p = rest.take().expect("a part per window");
            if r == last {
                parts.push((w[0]..w[1], p));
            } else {
                let (a, b) = p.split_at(w[1] - w[0]);
                parts.push((w[0]..w[1], a));
                rest = Some(b);
            }
        }
        self.each(parts, |_, (range, p)| f(range, p));
    }

    /// The bounds of the threads' parts of `0..n`: `count() + 1` entries.
    pub fn bounds(&self, n: usize) -> Vec<usize> {
        let t = self.count();
        (0..=t).map(|r| r * n / t).collect()
    }

    /// How long `samples` hand-overs with no work take, each to every thread and back, in
    /// nanoseconds: the fixed cost every stage on the pool pays. It follows the host's
    /// core-to-core latency, which on shared virtual machines is not a constant.
    pub fn hand_over_ns(&self, samples: usize) -> Vec<f64> {
        (0..samples)
            .map(|_| {
                let t0 = std::time::Instant::now();
                self.each(vec![(); self.count()], |_, ()| {});
                t0.elapsed().as_secs_f64() * 1e9
            })
            .collect()
    }

    /// `f(r, parts[r])` on thread r, for every r (one part per thread); returns when all
    /// are done.
    pub fn each<P: Send>(&self, parts: Vec<P>, f: impl Fn(usize, P) + Sync) {
        assert_eq!(parts.len(), self.count(), "one part per thread");
        #[cfg(feature = "parallel")]
        if let Some(pool) = &self.pool {
            let parts: Vec<std::sync::Mutex<Option<P>>> = parts.into_iter().map(|p| std::sync::Mutex::new(Some(p))).collect();
            pool.run(&|r| {
                let p = parts[r].lock().expect("one taker per part").take().expect("each part once");
                f(r, p)
            });
            return;
        }
        for (r, p) in parts.into_iter().enumerate() {
            f(r, p);
        }
    }
}

#[cfg(feature = "parallel")]
mod pool {
    use std::cell::UnsafeCell;
    use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
    use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
    use std::sync::{Arc, Mutex};
    use std::thread::JoinHandle;

    type Job = *const (dyn Fn(usize) + Sync);

    /// Spins before a waiting worker parks (about a millisecond).
    const SPINS: u32 = 1 << 14;

    struct Shared {
        /// Incremented for every job; a worker runs a job when it sees a new value.
        epoch: AtomicU64,
        /// Workers done with the current job.
        done: AtomicUsize,
        /// The current job, written before `epoch` is published.
        job: UnsafeCell<Option<Job>>,
        stop: AtomicBool,
        panicked: AtomicBool,
    }

    // SAFETY: `job` is written only by the thread holding `SpinPool::lock`, before the
    // release store of `epoch`, and read by workers after the acquire load that sees it;
    // the writer waits for every worker to finish before it writes again.
    unsafe impl Sync for Shared {}
    unsafe impl Send for Shared {}

    pub struct SpinPool {
        shared: Arc<Shared>,
        workers: Vec<JoinHandle<()>>,
        lock: Mutex<()>,
    }

    impl SpinPool {
        pub fn new(threads: usize) -> std::io::Result<Self> {
            let shared = Arc::new(Shared { epoch: AtomicU64::new(0), done: AtomicUsize::new(0), job: UnsafeCell::new(None), stop: AtomicBool::new(false), panicked: AtomicBool::new(false) });
            let mut workers = Vec::new();
            for index in 1..threads {
                let s = shared.clone();
                workers.push(std::thread::Builder::new().name(format!("grainlab-{index}")).spawn(move || worker(&s, index))?);
            }
            Ok(SpinPool { shared, workers, lock: Mutex::new(()) })
        }

        pub fn threads(&self) -> usize {
            self.workers.len() + 1
        }

        /// `f(r)` on every thread r (this one is 0); returns when all are done.
        pub fn run(&self, f: &(dyn Fn(usize) + Sync)) {
            let _guard = self.lock.lock().unwrap_or_else(|e| e.into_inner());
            let s = &*self.shared;
            s.done.store(0, Ordering::Relaxed);
            // SAFETY: the lifetime is erased only for the duration of this call: we wait
            // below until every worker is done with `f` (also when `f` panics here).
            unsafe { *s.job.get() = Some(std::mem::transmute::<&(dyn Fn(usize) + Sync), &'static (dyn Fn(usize) + Sync)>(f) as Job) };
            s.epoch.fetch_add(1, Ordering::Release);
            for w in &self.workers {
                w.thread().unpark();
            }
            let mine = catch_unwind(AssertUnwindSafe(|| f(0)));
            while s.done.load(Ordering::Acquire) < self.workers.len() {
                std::hint::spin_loop();
            }
            unsafe { *s.job.get() = None };
            if let Err(p) = mine {
                resume_unwind(p);
            }
            if s.panicked.swap(false, Ordering::Relaxed) {
                panic!("a grainlab worker thread panicked");
            }
        }
    }

    impl Drop for SpinPool {
        fn drop(&mut self) {
            self.shared.stop.store(true, Ordering::Release);
            for w in self.workers.drain(..) {
                w.thread().unpark();
                let _ = w.join();
            }
        }
    }

    fn worker(s: &Shared, index: usize) {
        let mut seen = 0;
        loop {
            let mut spins = 0u32;
            loop {
                let e = s.epoch.load(Ordering::Acquire);
                if e != seen {
                    seen = e;
                    break;
                }
                if s.stop.load(Ordering::Acquire) {
                    return;
                }
                spins += 1;
                if spins < SPINS {
                    std::hint::spin_loop();
                } else {
                    std::thread::park_timeout(std::time::Duration::from_millis(1));
                }
            }
            // SAFETY: published before the epoch we just saw; valid until we report done.
            let job = unsafe { (*s.job.get()).expect("a job with a new epoch") };
            if catch_unwind(AssertUnwindSafe(|| unsafe { (*job)(index) })).is_err() {
                s.panicked.store(true, Ordering::Relaxed);
            }
            s.done.fetch_add(1, Ordering::Release);
        }
    }
}
