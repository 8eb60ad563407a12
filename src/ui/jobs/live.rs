//! Following a trial another program is appending to, for the workbench:
//! [`crate::follow`] reads the complete lines as they land and solves the
//! growing trial in the background; this job turns what it has into
//! snapshots the trial screen draws (the rows so far, their correction,
//! solved up to the newest solve and extrapolated after it) and sends them
//! to the event loop as messages.

use crate::follow::{push, Extrapolation, Follower, FollowerConfig, LiveSource, Look};
use crate::metrics::trial_figures;
use crate::model::Model;
use crate::trial::{ImuSeries, Trial};
use crate::ui::loaded::{LiveTrace, Loaded};
use crate::ui::msg::{FollowJob, LiveEvent, LiveSnapshot, Msg};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Solves of the growing trial while its first drift window fills, every
/// this many seconds of trial time (as `acmw follow --warmup`).
pub const WARMUP_S: f64 = 10.0;

/// One follow: the reader, the follower, and the corrected samples so far.
pub struct LiveJob {
    job: FollowJob,
    source: LiveSource,
    follower: Follower,
    model: Model,
    /// The samples read so far, corrected: as solved before `solved`,
    /// extrapolated from the newest solve after it.
    corrected: Option<Trial>,
    solved: usize,
    solved_s: f64,
    /// Whether the file grew after the first look.
    grew: bool,
    looks: u64,
    /// Something changed since the last snapshot.
    changed: bool,
    note: Option<String>,
}

impl LiveJob {
    /// Starts following `job.path` (nothing read yet).
    pub fn new(job: FollowJob) -> LiveJob {
        let model = job
            .model
            .as_deref()
            .cloned()
            .unwrap_or_else(|| crate::trial::detect_model(&job.path));
        let config = FollowerConfig {
            model: model.clone(),
            limits: job.limits.clone(),
            limits_source: job.limits_source.clone(),
            settings: job.settings,
            variant: job.variant,
            extrapolation: Extrapolation::default(),
            warmup_s: WARMUP_S,
            until_s: None,
            calibration: None,
            pose: None,
        };
        LiveJob {
            follower: Follower::new(&job.file, config),
            source: LiveSource::new(&job.path, &model),
            model,
            job,
            corrected: None,
            solved: 0,
            solved_s: 0.0,
            grew: false,
            looks: 0,
            changed: false,
            note: None,
        }
    }

    /// Bytes of the file (or of every export of a folder) read so far.
    pub fn offset(&self) -> u64 {
        self.source.offset()
    }

    fn msg(&self, event: LiveEvent) -> Msg {
        Msg::Live {
            file: self.job.file.clone(),
            gen: self.job.gen,
            event,
        }
    }

    /// One look at the file and at the solver, then a snapshot when anything
    /// changed: the messages for the workbench (`Err`: the file cannot be
    /// followed, located).
    pub fn step(&mut self) -> Result<Vec<Msg>, String> {
        let mut out = self.look()?;
        out.extend(self.snapshot_if_changed());
        Ok(out)
    }

    /// A snapshot if anything changed since the last.
    pub fn snapshot_if_changed(&mut self) -> Vec<Msg> {
        if self.changed {
            self.snapshot()
        } else {
            vec![]
        }
    }

    /// One look at the file and at the solver: the rows appended since the
    /// last look (complete lines only), the solves that landed. Returns the
    /// restart it noticed, if any (`Err`: the file cannot be followed, located).
    pub fn look(&mut self) -> Result<Vec<Msg>, String> {
        let mut out = vec![];
        let before = self.source.offset();
        match self.source.poll().map_err(|e| e.to_string())? {
            Look::Nothing => {}
            Look::Restarted(reason) => {
                self.follower.restart();
                self.corrected = None;
                self.solved = 0;
                self.solved_s = 0.0;
                self.changed = true;
                let why = format!("{} {reason}: following it from its start", self.job.file);
                self.note = Some(why.clone());
                out.push(self.msg(LiveEvent::Restarted(why)));
            }
            look => {
                let range = push(&mut self.follower, look).map_err(|e| e.to_string())?;
                if !range.is_empty() {
                    if let Some(batch) = self.follower.corrected(range) {
                        match &mut self.corrected {
                            None => self.corrected = Some(batch),
                            Some(c) => append(c, batch),
                        }
                    }
                    self.changed = true;
                }
            }
        }
        if self.looks > 0 && self.source.offset() > before {
            self.grew = true;
        }
        self.looks += 1;
        self.take_solves();
        Ok(out)
    }

    /// Takes the solves that landed since the last look.
    fn take_solves(&mut self) {
        let landed = self.follower.poll_solved();
        self.landed(&landed);
    }

    /// Whether a solve asked for has not landed yet.
    pub fn solving(&self) -> bool {
        self.follower.solving()
    }

    /// Waits up to `timeout` for the next solve to land; the snapshot that
    /// shows it, if one landed.
    pub fn wait_solved(&mut self, timeout: Duration) -> Vec<Msg> {
        if self.await_solve(timeout) {
            self.snapshot()
        } else {
            vec![]
        }
    }

    /// Waits up to `timeout` for the next solve to land; whether one did.
    fn await_solve(&mut self, timeout: Duration) -> bool {
        if !self.follower.solving() {
            return false;
        }
        let landed = self.follower.wait_solved(timeout);
        self.landed(&landed);
        !landed.is_empty()
    }

    /// After solves landed: the newest solution's samples replace the
    /// extrapolated ones, and the samples after it are extrapolated anew.
    fn landed(&mut self, landed: &[crate::follow::Solved]) {
        let Some(last) = landed.last() else { return };
        self.note = last
            .error
            .as_ref()
            .map(|e| format!("could not solve 0-{:.1} s: {e}", last.point_s));
        self.changed = true;
        let (Some(trial), Some(prefix)) = (self.follower.trial(), self.follower.solved_trial())
        else {
            return;
        };
        let n = trial.len();
        let k = prefix.len().min(n);
        let mut corrected = (**prefix).clone();
        if let Some(rest) = self.follower.corrected(k..n) {
            append(&mut corrected, rest);
        }
        self.solved = k;
        self.solved_s = self.follower.solution().last_s;
        self.corrected = Some(corrected);
    }

    /// The rows so far as the workbench shows them (none before the first row).
    fn snapshot(&mut self) -> Vec<Msg> {
        self.changed = false;
        let (Some(trial), Some(corrected)) = (self.follower.trial(), &self.corrected) else {
            return vec![];
        };
        let mut trial = trial.clone();
        trial.name = self.job.file.clone();
        let before = trial_figures(&trial, None, None, &self.model, &self.job.limits);
        let format = self
            .follower
            .format()
            .unwrap_or(crate::trial::TrialFormat::QuatCsv);
        let loaded = Arc::new(Loaded {
            trial,
            model: self.model.clone(),
            // The hash of the bytes read so far: once the writer stops and
            // every byte was read, the whole file's, as its final reload
            // (read whole) records it. An export folder's comes with that
            // reload (nothing is saved while it grows).
            source: crate::correct::pipeline::Source {
                path: self.job.path.clone(),
                format,
                gzip: false,
                sha256: self.source.sha256_hex().unwrap_or_default(),
            },
            truth: None,
            truth_error: None,
            reference: None,
            reference_error: None,
            before,
            angles: Default::default(),
            pose: None,
            uncalibrated: None,
            glitches: vec![],
            on_disk: Default::default(),
        });
        let trace = LiveTrace {
            variant: self.job.variant,
            corrected: Arc::new(corrected.clone()),
            angles: Default::default(),
            solved: self.solved,
            solved_s: self.solved_s,
            solving: self.follower.solving(),
            grew: self.grew,
            note: self.note.clone(),
        };
        vec![self.msg(LiveEvent::Snapshot(Box::new(LiveSnapshot {
            loaded,
            trace,
        })))]
    }

    /// Stops following: the message that says so (`grew`: whether the file
    /// grew while followed, so that the final correction is due).
    pub fn finish(mut self, result: Result<(), String>) -> Msg {
        self.follower.stop();
        let grew = self.grew;
        self.msg(LiveEvent::Ended { result, grew })
    }
}

/// Appends `batch`'s samples (same IMUs, later times) to `trial`.
fn append(trial: &mut Trial, batch: Trial) {
    trial.time_s.extend(batch.time_s);
    for (s, b) in trial.imus.iter_mut().zip(batch.imus) {
        let ImuSeries {
            orientation, gyro, ..
        } = b;
        s.orientation.extend(orientation);
        if let (Some(g), Some(h)) = (&mut s.gyro, gyro) {
            g.extend(h);
        }
    }
}

/// Follows `job` until the file has not grown for `idle` (the writer
/// stopped) or `cancel` is set, looking every `poll` (and as soon as a solve
/// lands); each message goes to `send` (which returns false when nobody
/// listens any more). Snapshots of a long trial cost time (a copy of the
/// rows and their figures): one is sent after a change at most every `poll`,
/// and at least four times its own cost apart, so that building them takes
/// a fifth of a core at most.
pub fn run(
    job: FollowJob,
    cancel: &AtomicBool,
    poll: Duration,
    idle: Duration,
    send: impl Fn(Msg) -> bool,
) {
    let mut live = LiveJob::new(job);
    let mut last_growth = Instant::now();
    let mut next_snapshot = Instant::now();
    let result = loop {
        if cancel.load(Ordering::Relaxed) {
            return;
        }
        let before = live.offset();
        match live.look() {
            Ok(msgs) => {
                if !msgs.into_iter().all(&send) {
                    return;
                }
            }
            Err(e) => break Err(e),
        }
        if live.offset() != before {
            last_growth = Instant::now();
        }
        if Instant::now() >= next_snapshot {
            let start = Instant::now();
            let msgs = live.snapshot_if_changed();
            if !msgs.into_iter().all(&send) {
                return;
            }
            next_snapshot = Instant::now() + (start.elapsed() * 4).max(poll);
        }
        if last_growth.elapsed() >= idle && !live.solving() {
            break Ok(());
        }
        // Until the next look: a solve landing wakes it early.
        let solving = live.solving();
        if !live.await_solve(poll) && !solving {
            std::thread::sleep(poll);
        }
    };
    if !cancel.load(Ordering::Relaxed) {
        // The last rows read, then the end.
        let _ = live.snapshot_if_changed().into_iter().all(&send) && send(live.finish(result));
    }
}

/// Follows `job` once, as far as the file is written now, with every solve
/// due awaited: what a synchronous runner (tests, `acmw render`) sees.
pub fn follow_once(job: FollowJob) -> Vec<Msg> {
    let mut live = LiveJob::new(job);
    let mut out = vec![];
    let result = (|| {
        out.extend(live.step()?);
        while live.solving() {
            out.extend(live.wait_solved(Duration::from_secs(600)));
        }
        Ok(())
    })();
    out.push(live.finish(result));
    out
}
