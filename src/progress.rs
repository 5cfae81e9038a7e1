//! Progress reporting and cancellation for long calls. The callback is only ever called from
//! the thread that started the call (hosts' UI toolkits require it): parallel work reports
//! between its parallel sections, never from inside them.

use crate::error::{Error, Result};

/// A progress callback: `(fraction in [0,1], stage name) -> keep going?`.
pub type ProgressFn<'a> = dyn FnMut(f32, &str) -> bool + 'a;

/// Where a stage sits inside the whole call, so nested stages report a global fraction.
pub struct Progress<'a> {
    callback: Option<&'a mut ProgressFn<'a>>,
    start: f32,
    end: f32,
}

impl<'a> Progress<'a> {
    /// No reporting, never cancelled.
    pub fn none() -> Progress<'static> {
        Progress { callback: None, start: 0.0, end: 1.0 }
    }

    pub fn new(callback: &'a mut ProgressFn<'a>) -> Progress<'a> {
        Progress { callback: Some(callback), start: 0.0, end: 1.0 }
    }

    /// Reports `fraction` of the current stage; `Err(Cancelled)` when the callback says stop.
    pub fn report(&mut self, fraction: f32, stage: &str) -> Result<()> {
        let global = self.start + (self.end - self.start) * fraction.clamp(0.0, 1.0);
        let keep_going = match self.callback.as_mut() {
            Some(callback) => callback(global, stage),
            None => true,
        };
        if keep_going {
            Ok(())
        } else {
            Err(Error::Cancelled)
        }
    }

    /// A sub-stage covering `[from, to]` of this stage's range.
    pub fn stage(&mut self, from: f32, to: f32) -> Progress<'_> {
        let span = self.end - self.start;
        Progress {
            callback: self.callback.as_mut().map(|c| &mut **c as &mut ProgressFn<'_>),
            start: self.start + span * from,
            end: self.start + span * to,
        }
    }
}

/// The worker threads a call uses: a private pool of `count` threads, or rayon's global pool
/// (all cores) for `count == 0`.
pub struct Threads {
    pool: Option<rayon::ThreadPool>,
}

impl Threads {
    /// A pool of `count` threads (0 = rayon's global pool, one per core). More threads than
    /// the machine runs at once only take turns (a thousand make a small job hundreds of times
    /// slower), so the
    /// count is capped at [`Threads::count_for`]; results are the same for any count.
    pub fn new(count: usize) -> Result<Threads> {
        if count > Threads::MAX {
            return Err(Error::param(
                "threads",
                format!("{count} is absurd (0 = all cores, at most {})", Threads::MAX),
            ));
        }
        let pool = match count {
            0 => None,
            n => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(Threads::count_for(n))
                    .build()
                    .map_err(|e| Error::input(format!("cannot start {n} threads: {e}")))?,
            ),
        };
        Ok(Threads { pool })
    }

    /// The largest thread count accepted.
    /// cbindgen:ignore
    pub const MAX: usize = 1024;

    /// The threads a request for `count` gets: `count` (0 = all cores), at most one per core
    /// the machine runs at once.
    pub fn count_for(count: usize) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        if count == 0 {
            cores
        } else {
            count.min(cores)
        }
    }

    /// Runs `work` (which may use rayon's parallel iterators) on these threads.
    pub fn run<R: Send>(&self, work: impl FnOnce() -> R + Send) -> R {
        match &self.pool {
            Some(pool) => pool.install(work),
            None => work(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_stages_report_global_fractions_and_cancel() {
        let mut seen = Vec::new();
        let mut callback = |f: f32, s: &str| {
            seen.push((f, s.to_string()));
            f < 0.7
        };
        let mut progress = Progress::new(&mut callback);
        progress.report(0.0, "start").unwrap();
        let mut sub = progress.stage(0.5, 1.0);
        sub.report(0.3, "part of second half").unwrap();
        assert!(matches!(sub.report(1.0, "end"), Err(Error::Cancelled)));
        assert!((seen[1].0 - 0.65).abs() < 1e-6);
        assert_eq!(seen.len(), 3);
    }
}
