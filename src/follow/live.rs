//! The growing trial, its background solves and the correction of new rows.

use super::extrapolate::{Extrapolation, Solution};
use super::schedule::Schedule;
use crate::acm::RunControl;
use crate::calibration::AppliedCalibration;
use crate::correct::pipeline::{self, Preparation, Setup};
use crate::limits::{LimitTable, Settings};
use crate::model::Model;
use crate::pose::{PoseCalibration, PoseRecord};
use crate::trial::precision::Decimals;
use crate::trial::{
    csv_format_of_header, read_rows_from_str, ImuSeries, Trial, TrialError, TrialFormat,
};
use crate::variant::Variant;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

/// Tolerance (seconds) of the cut at a solve point, as the window layout's.
const EPS: f64 = 1e-9;

/// What a follower corrects with, and how.
#[derive(Debug, Clone)]
pub struct FollowerConfig {
    pub model: Model,
    pub limits: LimitTable,
    /// Where the table came from (a path or `<built-in NAME>`).
    pub limits_source: String,
    pub settings: Settings,
    pub variant: Variant,
    pub extrapolation: Extrapolation,
    /// Interval of the solves while the first window fills, seconds of trial
    /// time (0: none before the first window is complete).
    pub warmup_s: f64,
    /// Rows later than this many seconds after the first sample are left out
    /// (`None`: none are).
    pub until_s: Option<f64>,
    /// A functional calibration (`acmw calibrate`: a fixed rotation of each
    /// calibrated IMU's sensor frame, `G_R_FF = G_R_SF * R^-1`) applied to
    /// every prefix before it is solved and to every new row before its
    /// correction, as `acmw correct --calibration` applies it to the whole
    /// trial (`None`: rows are corrected as read).
    pub calibration: Option<AppliedCalibration>,
    /// A pose calibration with heading correction, applied after the
    /// functional one: nothing is solved, and rows go out as read, until a
    /// row later than its time or span arrives; then it is found on the rows
    /// so far, and applied to every prefix solved and every later row.
    pub pose: Option<PoseCalibration>,
}

impl FollowerConfig {
    /// The pipeline's view of this configuration.
    pub fn setup(&self) -> Setup<'_> {
        Setup {
            model: &self.model,
            limits: &self.limits,
            limits_source: &self.limits_source,
            settings: &self.settings,
        }
    }

    /// What is done to a prefix before it is corrected: the functional
    /// calibration, then the pose calibration, if any.
    pub fn preparation(&self) -> Preparation {
        Preparation {
            calibration: self.calibration.clone(),
            pose: self.pose,
        }
    }

    /// When the growing trial is solved again.
    pub fn schedule(&self) -> Schedule {
        Schedule {
            window_s: self.settings.window_s,
            hop_s: self.settings.hop_s,
            warmup_s: self.warmup_s,
        }
    }
}

/// A background solve that finished.
#[derive(Debug, Clone, PartialEq)]
pub struct Solved {
    /// Samples solved (a prefix of the trial).
    pub samples: usize,
    /// Trial time the prefix ends at: the solve point, seconds from the first sample.
    pub point_s: f64,
    /// Wall-clock time the solve took.
    pub elapsed: Duration,
    /// Why the prefix could not be corrected, if it could not (the previous
    /// solution stays in use).
    pub error: Option<String>,
}

struct Request {
    generation: u64,
    point_s: f64,
    trial: Trial,
}

struct Answer {
    generation: u64,
    solved: Solved,
    solution: Option<(Solution, Arc<Trial>)>,
}

/// A trial read as it grows: rows are added as their lines land
/// ([`Follower::push`]), prefixes are solved in a background thread at the
/// [`Schedule`]'s points, and each new row is corrected with the newest
/// solution, extrapolated ([`Follower::corrected`]).
pub struct Follower {
    origin: String,
    config: Arc<FollowerConfig>,
    /// Comment lines and the column header, as read.
    header: String,
    header_done: bool,
    format: Option<TrialFormat>,
    trial: Option<Trial>,
    next_point: usize,
    solution: Solution,
    /// The samples the newest solution was solved on, as it corrected them.
    solved_trial: Option<Arc<Trial>>,
    generation: u64,
    reached_until: bool,
    /// The pose calibration found once its samples were all read (or why it
    /// could not be found).
    pose: Option<Result<PoseRecord, String>>,
    /// Samples of the newest solve asked for, and of the newest answered, in
    /// this generation.
    asked: usize,
    answered: usize,
    requests: Option<mpsc::Sender<Request>>,
    answers: mpsc::Receiver<Answer>,
    cancel: Arc<AtomicBool>,
    worker: Option<std::thread::JoinHandle<()>>,
}

impl Follower {
    /// A follower of the file named `origin` (for errors and the trial's name).
    pub fn new(origin: &str, config: FollowerConfig) -> Follower {
        let config = Arc::new(config);
        let (requests, inbox) = mpsc::channel::<Request>();
        let (outbox, answers) = mpsc::channel::<Answer>();
        let cancel = Arc::new(AtomicBool::new(false));
        let worker = {
            let config = Arc::clone(&config);
            let cancel = Arc::clone(&cancel);
            std::thread::Builder::new()
                .name("acmw-follow-solver".into())
                .spawn(move || solver(&config, &inbox, &outbox, &cancel))
                .expect("a thread can be started")
        };
        Follower {
            origin: origin.to_string(),
            config,
            header: String::new(),
            header_done: false,
            format: None,
            trial: None,
            next_point: 0,
            solution: Solution::identity(0),
            solved_trial: None,
            generation: 0,
            reached_until: false,
            pose: None,
            asked: 0,
            answered: 0,
            requests: Some(requests),
            answers,
            cancel,
            worker: Some(worker),
        }
    }

    /// Forgets everything read (the file restarted); solves under way are ignored.
    pub fn restart(&mut self) {
        self.header.clear();
        self.header_done = false;
        self.format = None;
        self.trial = None;
        self.next_point = 0;
        self.solution = Solution::identity(0);
        self.solved_trial = None;
        self.generation += 1;
        self.reached_until = false;
        self.pose = None;
        self.asked = 0;
        self.answered = 0;
    }

    /// What it corrects with.
    pub fn config(&self) -> &FollowerConfig {
        &self.config
    }

    /// The rows read so far (`None` before the first).
    pub fn trial(&self) -> Option<&Trial> {
        self.trial.as_ref()
    }

    /// The format the header names (canonical or Euler CSV), once it was read.
    pub fn format(&self) -> Option<TrialFormat> {
        self.format
    }

    /// The solution new rows are corrected with.
    pub fn solution(&self) -> &Solution {
        &self.solution
    }

    /// The samples the newest solution was solved on (a prefix of the
    /// trial), corrected by that solve as `acmw correct` corrects a trial of
    /// those samples; `None` before the first solve. Samples after it are
    /// corrected by extrapolation ([`Follower::corrected`]).
    pub fn solved_trial(&self) -> Option<&Arc<Trial>> {
        self.solved_trial.as_ref()
    }

    /// Whether a row past `until_s` was seen: the trial is complete.
    pub fn reached_until(&self) -> bool {
        self.reached_until
    }

    /// Adds the complete lines `text` (from 1-based line `first_line` of the
    /// file): the header first, then data rows. Returns the indices of the
    /// new samples (empty when there were none). Errors are located in the file.
    pub fn push(&mut self, text: &str, first_line: u64) -> Result<Range<usize>, TrialError> {
        let before = self.trial.as_ref().map_or(0, Trial::len);
        let mut line = first_line;
        let mut rest = text;
        while !self.header_done && !rest.is_empty() {
            let end = rest.find('\n').map_or(rest.len(), |i| i + 1);
            let (l, r) = rest.split_at(end);
            self.header.push_str(l);
            let t = l.trim_start_matches('\u{feff}').trim();
            if !t.is_empty() && !t.starts_with('#') {
                self.header_done = true;
                self.format = Some(csv_format_of_header(t));
            }
            rest = r;
            line += 1;
        }
        if self.reached_until || rest.trim().is_empty() {
            return Ok(before..before);
        }
        let batch = read_rows_from_str(&self.header, rest, line, &self.origin, &self.config.model)?;
        // The first data row's line, for an error about its time.
        let row_line = line
            + rest
                .split('\n')
                .position(|l| !l.trim().is_empty())
                .unwrap_or(0) as u64;
        self.add(batch, row_line)
    }

    /// Adds samples read by another reader (the aligned rows of Xsens
    /// exports, [`crate::trial::xsens_trial::GrowingExports`]): the same
    /// IMUs in the same order at each call, later times. Returns the
    /// indices of the new samples.
    pub fn push_samples(&mut self, batch: Trial) -> Result<Range<usize>, TrialError> {
        let before = self.trial.as_ref().map_or(0, Trial::len);
        if self.reached_until || batch.is_empty() {
            return Ok(before..before);
        }
        if let Some(trial) = &self.trial {
            let names = |t: &Trial| t.imus.iter().map(|s| s.name.clone()).collect::<Vec<_>>();
            if names(trial) != names(&batch) {
                return Err(TrialError::file(
                    &self.origin,
                    format!(
                        "the IMUs changed from {} to {}; expected the same IMUs in every batch",
                        names(trial).join(", "),
                        names(&batch).join(", ")
                    ),
                ));
            }
        }
        self.add(batch, 0)
    }

    /// Adds a batch of rows (the first at `row_line` of the file, 0 when
    /// not from one line of it).
    fn add(&mut self, mut batch: Trial, row_line: u64) -> Result<Range<usize>, TrialError> {
        let before = self.trial.as_ref().map_or(0, Trial::len);
        if let Some(prev) = self.trial.as_ref().and_then(|t| t.time_s.last().copied()) {
            let t = batch.time_s[0];
            if t <= prev {
                let message = format!("time {t} does not follow the previous time {prev}; expected times to strictly increase");
                return Err(if row_line == 0 {
                    TrialError::file(&self.origin, message)
                } else {
                    TrialError::at(&self.origin, row_line, 1, message)
                });
            }
        }
        let t0 = self.trial.as_ref().map_or(batch.time_s[0], |t| t.time_s[0]);
        if let Some(until) = self.config.until_s {
            let keep = batch.time_s.partition_point(|&t| t - t0 <= until + EPS);
            if keep < batch.len() {
                self.reached_until = true;
                let idx: Vec<usize> = (0..keep).collect();
                batch = batch.select(&idx, &batch.name.clone());
            }
        }
        match &mut self.trial {
            None => self.trial = Some(batch),
            Some(trial) => append(trial, batch),
        }
        let after = self.trial.as_ref().map_or(0, Trial::len);
        if after > before {
            self.find_pose();
            self.schedule_solve();
        }
        Ok(before..after)
    }

    /// The pose calibration, once a row later than its time or span was
    /// read (`None` before; an error when it cannot be done).
    pub fn pose(&self) -> Option<&Result<PoseRecord, String>> {
        self.pose.as_ref()
    }

    /// Whether rows are still waiting for the pose calibration's samples
    /// (they go out as read, and nothing is solved).
    pub fn awaiting_pose(&self) -> bool {
        self.config.pose.is_some() && !matches!(self.pose, Some(Ok(_)))
    }

    /// Finds the pose calibration on the rows so far once its samples are in.
    fn find_pose(&mut self) {
        let (Some(p), None, Some(trial)) = (&self.config.pose, &self.pose, &self.trial) else {
            return;
        };
        let t0 = trial.time_s[0];
        if trial.time_s[trial.len() - 1] - t0 <= p.at.end_s() + EPS {
            return;
        }
        let mut rows = trial.clone();
        if let Some(c) = &self.config.calibration {
            let _ = c.apply(&mut rows, &self.config.model);
        }
        self.pose = Some(
            crate::pose::calibrate(&rows, &self.config.model, p)
                .map(|(_, r)| r)
                .map_err(|e| e.to_string()),
        );
    }

    /// Sends the newest prefix due to the solver, when a solve point was passed.
    fn schedule_solve(&mut self) {
        if self.awaiting_pose() {
            return;
        }
        let Some(trial) = &self.trial else { return };
        let t0 = trial.time_s[0];
        let elapsed = trial.time_s[trial.len() - 1] - t0;
        let schedule = self.config.schedule();
        let Some(k) = schedule.last_reached(elapsed) else {
            return;
        };
        if k < self.next_point {
            return;
        }
        self.next_point = k + 1;
        let point_s = schedule.point(k);
        // A prefix solved must hold the pose calibration's samples, all of them.
        if self
            .config
            .pose
            .is_some_and(|p| point_s <= p.at.end_s() + EPS)
        {
            return;
        }
        let n = trial.time_s.partition_point(|&t| t - t0 < point_s - EPS);
        if n < 2 {
            return;
        }
        let prefix = prefix(trial, n);
        if let Some(tx) = &self.requests {
            self.asked = n;
            let _ = tx.send(Request {
                generation: self.generation,
                point_s,
                trial: prefix,
            });
        }
    }

    /// The solves that finished since the last call; the newest becomes the
    /// solution new rows are corrected with.
    pub fn poll_solved(&mut self) -> Vec<Solved> {
        let mut out = Vec::new();
        while let Ok(a) = self.answers.try_recv() {
            self.take(a, &mut out);
        }
        out
    }

    fn take(&mut self, a: Answer, out: &mut Vec<Solved>) {
        if a.generation != self.generation {
            return;
        }
        // The solver skips requests that queued behind a newer one.
        self.answered = self.answered.max(a.solved.samples);
        if let Some((s, corrected)) = a.solution {
            if s.samples >= self.solution.samples {
                self.solution = s;
                self.solved_trial = Some(corrected);
            }
        }
        out.push(a.solved);
    }

    /// Whether a solve asked for has not answered yet.
    pub fn solving(&self) -> bool {
        self.answered < self.asked
    }

    /// Waits up to `timeout` for the next solve to finish (then as [`Follower::poll_solved`]).
    pub fn wait_solved(&mut self, timeout: Duration) -> Vec<Solved> {
        match self.answers.recv_timeout(timeout) {
            Ok(a) => {
                let mut out = Vec::new();
                self.take(a, &mut out);
                out.extend(self.poll_solved());
                out
            }
            Err(_) => Vec::new(),
        }
    }

    /// Samples `range` calibrated (when the configuration names a
    /// functional calibration) and corrected with the newest solution
    /// (extrapolated past the samples it was solved on), as a trial of
    /// those samples.
    pub fn corrected(&self, range: Range<usize>) -> Option<Trial> {
        let trial = self.trial.as_ref()?;
        let t0 = trial.time_s[0];
        let idx: Vec<usize> = range.clone().collect();
        if self.awaiting_pose() {
            let mut rows = trial.select(&idx, &trial.name);
            rows.warnings.clear();
            return Some(rows);
        }
        Some(match (&self.config.calibration, &self.pose) {
            (None, None) => self.solution.apply(trial, range, t0),
            (calibration, pose) => {
                let mut rows = trial.select(&idx, &trial.name);
                // IMUs the calibration names but the trial lacks: the final
                // correction reports them.
                if let Some(c) = calibration {
                    let _ = c.apply(&mut rows, &self.config.model);
                }
                if let Some(Ok(p)) = pose {
                    p.apply(&mut rows);
                }
                self.solution.apply(&rows, 0..rows.len(), t0)
            }
        })
    }

    /// Stops the background solver (a solve under way stops at its next window).
    pub fn stop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
        self.requests = None;
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
    }
}

impl Drop for Follower {
    fn drop(&mut self) {
        self.stop();
    }
}

/// The first `n` samples of `trial`.
fn prefix(trial: &Trial, n: usize) -> Trial {
    Trial {
        name: trial.name.clone(),
        time_s: trial.time_s[..n].to_vec(),
        imus: trial
            .imus
            .iter()
            .map(|s| {
                ImuSeries::new(s.name.clone(), s.orientation[..n].to_vec())
                    .with_gyro(s.gyro.as_ref().map(|g| g[..n].to_vec()))
            })
            .collect(),
        warnings: trial.warnings.clone(),
        orientation_decimals: trial.orientation_decimals,
    }
}

/// Appends `batch`'s samples (same IMUs, later times) to `trial`, and its
/// decimal places (as if read at once).
fn append(trial: &mut Trial, batch: Trial) {
    trial.orientation_decimals =
        Decimals::merge(trial.orientation_decimals, batch.orientation_decimals);
    trial.time_s.extend(batch.time_s);
    for (s, b) in trial.imus.iter_mut().zip(batch.imus) {
        s.orientation.extend(b.orientation);
        if let (Some(g), Some(h)) = (&mut s.gyro, b.gyro) {
            g.extend(h);
        }
    }
}

/// The background solver: solves the newest prefix asked for, skipping
/// older requests that queued up meanwhile.
fn solver(
    config: &FollowerConfig,
    inbox: &mpsc::Receiver<Request>,
    outbox: &mpsc::Sender<Answer>,
    cancel: &AtomicBool,
) {
    let preparation = config.preparation();
    while let Ok(mut req) = inbox.recv() {
        while let Ok(newer) = inbox.try_recv() {
            req = newer;
        }
        if cancel.load(Ordering::Relaxed) {
            return;
        }
        let start = Instant::now();
        let samples = req.trial.len();
        let setup = config.setup();
        let control = RunControl {
            cancel: Some(cancel),
            progress: None,
        };
        let result = pipeline::prepare(req.trial, setup, &preparation)
            .map_err(|e| e.to_string())
            .and_then(|p| {
                pipeline::correct(&p.trial, setup, config.variant, &control)
                    .map(|c| {
                        let s = Solution::new(&p.trial, &c, config.extrapolation);
                        (s, Arc::new(c.corrected))
                    })
                    .map_err(|_| "cancelled".to_string())
            });
        let (solution, error) = match result {
            Ok(s) => (Some(s), None),
            Err(e) => (None, Some(e)),
        };
        let answer = Answer {
            generation: req.generation,
            solved: Solved {
                samples,
                point_s: req.point_s,
                elapsed: start.elapsed(),
                error,
            },
            solution,
        };
        if outbox.send(answer).is_err() {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trial::{read_trial_from_str, trial_to_string};

    fn config(until_s: Option<f64>) -> FollowerConfig {
        FollowerConfig {
            model: Model::infant13(),
            limits: LimitTable::default_table(),
            limits_source: "<built-in>".into(),
            settings: Settings::default(),
            variant: Variant::DriftCentroid,
            extrapolation: Extrapolation::default(),
            warmup_s: 0.0,
            until_s,
            calibration: None,
            pose: None,
        }
    }

    #[test]
    fn rows_pushed_in_any_batches_are_the_trial_the_file_reader_reads() {
        let sim = crate::simulate::simulate(&crate::simulate::SimConfig {
            duration_s: 6.0,
            ..crate::simulate::SimConfig::full_body(3)
        })
        .unwrap();
        let text = format!(
            "# a comment\n\n{}",
            trial_to_string(&sim.trial, TrialFormat::EulerCsv)
        );
        let whole =
            read_trial_from_str(&text, "x.csv", TrialFormat::EulerCsv, &Model::infant13()).unwrap();
        let lines: Vec<&str> = text.split_inclusive('\n').collect();
        let mut f = Follower::new("x.csv", config(None));
        let (mut at, mut k) = (0, 1usize);
        while at < lines.len() {
            let n = (k % 7 + 1).min(lines.len() - at);
            f.push(&lines[at..at + n].concat(), at as u64 + 1).unwrap();
            at += n;
            k += 3;
        }
        assert_eq!(f.format(), Some(TrialFormat::EulerCsv));
        let got = f.trial().unwrap();
        assert_eq!(got.time_s, whole.time_s);
        assert_eq!(got.imus, whole.imus);
        // Before any solve the rows pass through unchanged.
        let c = f.corrected(0..got.len()).unwrap();
        assert_eq!(c.imus, whole.imus);
        // A bad row and a time going back are located at their lines.
        let last = *whole.time_s.last().unwrap();
        let n = lines.len() as u64;
        let e = f.push("1e9,oops\n", n + 1).unwrap_err().to_string();
        assert!(e.starts_with(&format!("x.csv:{}:", n + 1)), "{e}");
        let row = lines[lines.len() - 1].replacen(&format!("{last}"), "0.5", 1);
        let e = f.push(&format!("\n{row}"), n + 1).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("x.csv:{}:1:", n + 2)) && e.contains("strictly increase"),
            "{e}"
        );
        // --until keeps the rows up to its time.
        let mut f = Follower::new("x.csv", config(Some(2.0)));
        f.push(&text, 1).unwrap();
        assert!(f.reached_until());
        let t = &f.trial().unwrap().time_s;
        assert!(
            *t.last().unwrap() - t[0] <= 2.0 + 1e-9 && t.len() == 101,
            "{}",
            t.len()
        );
    }
}
