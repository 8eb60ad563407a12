//! `acmw simulate`: write a simulated trial and its truth beside it.

use acm_workbench::simulate::truth::{self, Truth};
use acm_workbench::simulate::{
    self, HeadingDrift, ImuMisalignment, KneeAxis, KneeImu, Misalignment, SensorSlip, SimConfig,
    RANDOM_MISALIGNMENT_DEG,
};
use anyhow::Context;
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};

/// Exit code of a configuration that cannot be simulated (a usage error).
const EXIT_USAGE: i32 = 2;

#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(subcommand)]
    pub what: What,
}

#[derive(Debug, Subcommand)]
pub enum What {
    /// Thesis 4.1 knee test: static thigh, calf flexing 15-75 deg at 5 cycles/min,
    /// one IMU misaligned about X or Z (IMUs l_thigh and l_calf).
    Knee(KneeArgs),
    /// The 13 IMUs of infant13: crawling-like motion, random 5-30 deg misalignment
    /// of every non-base IMU, optional heading drift, noise.
    FullBody(FullBodyArgs),
    /// Mueller et al. elbow test: static upper arm, forearm flexing 20-130 deg and
    /// pronating +-28 deg, both IMUs tilted off their hinge axes (IMUs l_upper_arm
    /// and l_forearm).
    Elbow(ElbowArgs),
    /// A named configuration (knee_calf_z15, full_body_clean, full_body_drift, elbow_20);
    /// the common options override it.
    Preset(PresetArgs),
    /// A functional calibration recording (Ricci et al. 2014 protocol) with known
    /// sensor-to-frame rotations, sloppy movements and noise.
    Calibration(super::calibrate::SimulateCalibrationArgs),
}

#[derive(Debug, Args)]
pub struct KneeArgs {
    /// The misaligned IMU.
    #[arg(long, value_parser = super::common::named_parser::<KneeImu>(), default_value = "calf")]
    pub imu: KneeImu,
    /// The sensor axis of the misalignment.
    #[arg(long, value_parser = super::common::named_parser::<KneeAxis>(), default_value = "z")]
    pub axis: KneeAxis,
    /// Misalignment angle, degrees.
    #[arg(long, default_value_t = 15.0, allow_negative_numbers = true)]
    pub angle: f64,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Args)]
pub struct ElbowArgs {
    /// Misalignment of each IMU about a random axis perpendicular to its hinge
    /// axis, degrees.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pub angle: f64,
    /// Further misalignment by a rotation vector in degrees in the sensor frame,
    /// IMU:X:Y:Z (repeatable), e.g. a turn about the hinge axis.
    #[arg(long = "misalign", value_parser = parse_misalignment, allow_hyphen_values = true)]
    pub misalign: Vec<ImuMisalignment>,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Args)]
pub struct FullBodyArgs {
    /// Smallest and largest random misalignment angle, degrees.
    #[arg(long, num_args = 2, value_names = ["MIN", "MAX"])]
    pub misalign_range: Option<Vec<f64>>,
    /// Misalign only the given IMUs instead, by a rotation vector in degrees in the
    /// sensor frame, IMU:X:Y:Z (repeatable).
    #[arg(long = "misalign", value_parser = parse_misalignment, allow_hyphen_values = true)]
    pub misalign: Vec<ImuMisalignment>,
    /// No misalignment at all.
    #[arg(long, conflicts_with_all = ["misalign", "misalign_range"])]
    pub aligned: bool,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Args)]
pub struct PresetArgs {
    /// Preset name.
    #[arg(value_parser = simulate::PRESETS)]
    pub name: String,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Args)]
pub struct CommonArgs {
    /// Trial length, seconds [default: 300, preset's for a preset].
    #[arg(long)]
    pub duration: Option<f64>,
    /// Sampling rate, Hz [default: 50].
    #[arg(long)]
    pub rate: Option<f64>,
    /// Random seed [default: 0].
    #[arg(long)]
    pub seed: Option<u64>,
    /// RMS orientation noise per sample, degrees [default: 0 knee, 0.3 full body, 0.5 elbow].
    #[arg(long)]
    pub noise: Option<f64>,
    /// Heading drift IMU:START_S:RATE_DEG_S about the global vertical (repeatable).
    #[arg(long, value_parser = parse_drift, allow_hyphen_values = true)]
    pub drift: Vec<HeadingDrift>,
    /// Sensor slippage IMU:START_S:RATE_DEG_S:AX:AY:AZ, a rotation about a
    /// sensor-frame axis growing from START_S (repeatable).
    #[arg(long, value_parser = parse_slip, allow_hyphen_values = true)]
    pub slip: Vec<SensorSlip>,
    /// Also write gyroscope columns <imu>_gx,<imu>_gy,<imu>_gz: each sensor's
    /// angular rate in its own frame, rad/s, from the true motion through the
    /// misalignment (drift and slippage included).
    #[arg(long)]
    pub gyro: bool,
    /// White noise on the gyroscope readings, standard deviation per axis,
    /// deg/s [default: 0].
    #[arg(long, value_name = "DEG_S", requires = "gyro")]
    pub gyro_noise: Option<f64>,
    /// Output trial file (`.csv` or `.csv.gz`); the truth goes beside it.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Round the written quaternion components to this many decimals, as a
    /// sensor's output resolution (6 decimals is under 1e-4 deg) [default: exact].
    #[arg(long)]
    pub decimals: Option<u32>,
    /// Write only NAME.truth.json; the truth's segment orientations are then
    /// simulated again from it when needed (deterministic), which keeps folders small.
    #[arg(long)]
    pub truth_json_only: bool,
    /// Also write the true joint angles as a reference CSV
    /// (`time,<joint>_x,<joint>_y,<joint>_z`, degrees) for `acmw report --reference`.
    #[arg(long, value_name = "FILE.csv")]
    pub reference_csv: Option<PathBuf>,
    /// Shift the reference CSV's times by S seconds (a clock that started S
    /// earlier), to try the lag search.
    #[arg(
        long,
        value_name = "S",
        requires = "reference_csv",
        allow_negative_numbers = true
    )]
    pub reference_lag: Option<f64>,
}

fn parse_drift(s: &str) -> Result<HeadingDrift, String> {
    let parts: Vec<&str> = s.split(':').collect();
    let [imu, start, rate] = parts[..] else {
        return Err(format!("expected IMU:START_S:RATE_DEG_S, found '{s}'"));
    };
    let num = |v: &str, what: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|_| format!("{what} '{v}' is not a number"))
    };
    Ok(HeadingDrift {
        imu: imu.trim().to_string(),
        start_s: num(start, "start")?,
        rate_deg_s: num(rate, "rate")?,
    })
}

fn parse_slip(s: &str) -> Result<SensorSlip, String> {
    let parts: Vec<&str> = s.split(':').collect();
    let [imu, start, rate, ax, ay, az] = parts[..] else {
        return Err(format!(
            "expected IMU:START_S:RATE_DEG_S:AX:AY:AZ, found '{s}'"
        ));
    };
    let num = |v: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|_| format!("'{v}' is not a number"))
    };
    Ok(SensorSlip {
        imu: imu.trim().to_string(),
        start_s: num(start)?,
        rate_deg_s: num(rate)?,
        axis: [num(ax)?, num(ay)?, num(az)?],
    })
}

fn parse_misalignment(s: &str) -> Result<ImuMisalignment, String> {
    let parts: Vec<&str> = s.split(':').collect();
    let [imu, x, y, z] = parts[..] else {
        return Err(format!("expected IMU:X:Y:Z (degrees), found '{s}'"));
    };
    let num = |v: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|_| format!("'{v}' is not a number"))
    };
    Ok(ImuMisalignment {
        imu: imu.trim().to_string(),
        rotvec_deg: [num(x)?, num(y)?, num(z)?],
    })
}

impl CommonArgs {
    fn apply(&self, cfg: &mut SimConfig) {
        if let Some(d) = self.duration {
            cfg.duration_s = d;
        }
        if let Some(r) = self.rate {
            cfg.rate_hz = r;
        }
        if let Some(s) = self.seed {
            cfg.seed = s;
        }
        if let Some(n) = self.noise {
            cfg.noise_deg = n;
        }
        if !self.drift.is_empty() {
            cfg.drifts = self.drift.clone();
        }
        if !self.slip.is_empty() {
            cfg.slips = self.slip.clone();
        }
        if self.gyro {
            cfg.gyro = Some(simulate::GyroSim {
                noise_deg_s: self.gyro_noise.unwrap_or(0.0),
            });
        }
    }
}

/// Runs `acmw simulate`.
pub fn run(args: SimulateArgs) -> anyhow::Result<i32> {
    let (mut cfg, common) = match args.what {
        What::Calibration(a) => return super::calibrate::simulate_run(a),
        What::Knee(a) => (SimConfig::knee(a.imu, a.axis, a.angle), a.common),
        What::Elbow(a) => {
            let mut cfg = SimConfig::elbow(0, a.angle);
            if !a.misalign.is_empty() {
                cfg.misalignment = Misalignment::Fixed { imus: a.misalign };
            }
            (cfg, a.common)
        }
        What::FullBody(a) => {
            let mut cfg = SimConfig::full_body(0);
            cfg.misalignment = if a.aligned {
                Misalignment::None
            } else if !a.misalign.is_empty() {
                Misalignment::Fixed { imus: a.misalign }
            } else {
                let r = a.misalign_range.unwrap_or(RANDOM_MISALIGNMENT_DEG.to_vec());
                Misalignment::Random {
                    min_deg: r[0],
                    max_deg: r[1],
                }
            };
            (cfg, a.common)
        }
        What::Preset(a) => (
            simulate::preset(&a.name).context("unknown preset")?,
            a.common,
        ),
    };
    common.apply(&mut cfg);
    let out = &common.output;
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if !(name.ends_with(".csv") || name.ends_with(".csv.gz")) || truth::is_truth_file(out) {
        eprintln!(
            "acmw: the output must be a trial file ending in .csv or .csv.gz (not a .truth file), found '{}'",
            out.display()
        );
        return Ok(EXIT_USAGE);
    }
    let sim = match simulate::simulate(&cfg) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("acmw: {e}");
            return Ok(EXIT_USAGE);
        }
    };
    let mut trial = sim.trial;
    trial.name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let trial = match common.decimals {
        Some(d) => simulate::round_orientations(&trial, d),
        None => trial,
    };
    let (truth_csv, truth_json) = save(&trial, &sim.truth, out, common.truth_json_only)?;
    if let Some(path) = &common.reference_csv {
        write_reference(&sim.truth, path, common.reference_lag.unwrap_or(0.0))?;
        outln!(
            "wrote {} (true joint angles, reference CSV)",
            path.display()
        )?;
    }

    outln!(
        "wrote {}: {} IMUs, {} samples ({} s at {} Hz), seed {}, noise {} deg",
        out.display(),
        trial.imus.len(),
        trial.len(),
        cfg.duration_s,
        cfg.rate_hz,
        cfg.seed,
        cfg.noise_deg
    )?;
    let misaligned: Vec<String> = sim
        .truth
        .meta
        .misalignments
        .iter()
        .filter_map(|(imu, q)| {
            let a =
                acm_workbench::rotation::angle_deg(&acm_workbench::rotation::quat_from_wxyz(*q));
            (a > 1e-9).then(|| format!("{imu} {a:.1}"))
        })
        .collect();
    if let Some(g) = &cfg.gyro {
        outln!(
            "  gyroscopes: <imu>_gx,_gy,_gz in rad/s (sensor frame), white noise {} deg/s per axis",
            g.noise_deg_s
        )?;
    }
    if misaligned.is_empty() {
        outln!("  misalignment: none")?;
    } else {
        outln!("  misalignment (deg): {}", misaligned.join(", "))?;
    }
    for d in &cfg.drifts {
        outln!(
            "  heading drift: {} from {} s at {} deg/s",
            d.imu,
            d.start_s,
            d.rate_deg_s
        )?;
    }
    for d in &cfg.slips {
        outln!(
            "  sensor slippage: {} from {} s at {} deg/s about sensor axis {:?}",
            d.imu,
            d.start_s,
            d.rate_deg_s,
            d.axis
        )?;
    }
    outln!("wrote {} (segment orientations)", truth_csv.display())?;
    outln!(
        "wrote {} (configuration, misalignments, drifts)",
        truth_json.display()
    )?;
    Ok(0)
}

/// Writes the trial and its truth files; returns the truth paths.
fn save(
    trial: &acm_workbench::trial::Trial,
    truth: &Truth,
    out: &Path,
    json_only: bool,
) -> anyhow::Result<(PathBuf, PathBuf)> {
    acm_workbench::trial::write_trial(trial, out, acm_workbench::trial::TrialFormat::QuatCsv)?;
    if json_only {
        let (csv, json) = truth::truth_paths(out);
        truth.meta.save(&json)?;
        return Ok((csv, json));
    }
    Ok(truth.save_beside(out)?)
}

/// The truth's joint angles as a reference CSV, times shifted by `lag_s`.
fn write_reference(truth: &Truth, path: &Path, lag_s: f64) -> anyhow::Result<()> {
    let model = acm_workbench::model::Model::builtin(simulate::MODEL)?;
    let mut columns = Vec::new();
    for joint in &model.joints {
        let Some(angles) = acm_workbench::metrics::joint_angles(&truth.segments, joint) else {
            continue;
        };
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            columns.push((
                format!("{}_{axis}", joint.name),
                angles.iter().map(|a| a[k]).collect(),
            ));
        }
    }
    let time: Vec<f64> = truth.segments.time_s.iter().map(|t| t + lag_s).collect();
    acm_workbench::reference::write_csv(path, &time, &columns)
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simulate_cli_parses_drift_and_misalignment() {
        let d = parse_drift("l_calf:60:0.05").unwrap();
        assert_eq!(
            (d.imu.as_str(), d.start_s, d.rate_deg_s),
            ("l_calf", 60.0, 0.05)
        );
        assert_eq!(parse_drift("r_foot:0:-0.1").unwrap().rate_deg_s, -0.1);
        assert!(parse_drift("l_calf:60").is_err());
        assert!(parse_drift("l_calf:x:1").unwrap_err().contains("start"));
        let m = parse_misalignment("head:0:-20:5").unwrap();
        assert_eq!((m.imu.as_str(), m.rotvec_deg), ("head", [0.0, -20.0, 5.0]));
        assert!(parse_misalignment("head:1:2").is_err());
    }

    #[test]
    fn simulate_cli_writes_trial_and_truth() {
        use clap::Parser;
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("k.csv.gz");
        let cli = crate::cli::Cli::try_parse_from([
            "acmw",
            "simulate",
            "knee",
            "--imu",
            "calf",
            "--axis",
            "z",
            "--angle",
            "15",
            "--duration",
            "2",
            "-o",
            out.to_str().unwrap(),
        ])
        .unwrap();
        assert_eq!(crate::cli::run(cli), 0);
        assert!(out.exists());
        assert!(dir.path().join("k.truth.csv.gz").exists());
        let json = std::fs::read_to_string(dir.path().join("k.truth.json")).unwrap();
        let meta =
            acm_workbench::simulate::truth::TruthMeta::from_json(&json, "k.truth.json").unwrap();
        assert_eq!(meta.config.duration_s, 2.0);
        assert_eq!(meta.config.gyro, None);
        assert!(!json.contains("gyro"), "{json}");
    }

    #[test]
    fn simulate_cli_writes_gyro_columns() {
        use acm_workbench::model::Model;
        use clap::Parser;
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("e.csv");
        let args = [
            "acmw",
            "simulate",
            "elbow",
            "--duration",
            "3",
            "--gyro",
            "--gyro-noise",
            "0.5",
            "-o",
        ];
        let mut argv: Vec<&str> = args.to_vec();
        argv.push(out.to_str().unwrap());
        let cli = crate::cli::Cli::try_parse_from(&argv).unwrap();
        assert_eq!(crate::cli::run(cli), 0);
        let text = std::fs::read_to_string(&out).unwrap();
        assert!(
            text.starts_with("time,l_upper_arm_qw,l_upper_arm_qx,l_upper_arm_qy,l_upper_arm_qz,l_upper_arm_gx,l_upper_arm_gy,l_upper_arm_gz,l_forearm_qw"),
            "{}",
            &text[..200]
        );
        let trial = acm_workbench::trial::read_trial(&out, &Model::infant13()).unwrap();
        assert!(trial
            .imus
            .iter()
            .all(|s| s.gyro.as_ref().map(Vec::len) == Some(150)));
        let json = std::fs::read_to_string(dir.path().join("e.truth.json")).unwrap();
        let meta =
            acm_workbench::simulate::truth::TruthMeta::from_json(&json, "e.truth.json").unwrap();
        assert_eq!(meta.config.gyro.map(|g| g.noise_deg_s), Some(0.5));
        // The noise needs --gyro.
        let argv = [
            "acmw",
            "simulate",
            "elbow",
            "--gyro-noise",
            "1",
            "-o",
            "x.csv",
        ];
        assert!(crate::cli::Cli::try_parse_from(argv).is_err());
    }
}
