//! `acmw calibrate`: functional calibration of a recording (Ricci et al. 2014);
//! `acmw simulate calibration`: a simulated recording with its truth; and the
//! `--calibration FILE` step that `correct` and `report` run before the ACM.

use acm_workbench::calibration::simulate::{self, CalibSimConfig, Sloppiness};
use acm_workbench::calibration::{
    calibrate, default_output, Calibration, Protocol, Recording, DEFAULT_PROTOCOL_NAME,
};
use acm_workbench::rotation::{angle_between_deg, angle_deg, Quat};
use clap::Args;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// The calibration recording (CSV: time, label, <imu>_ax..._gz; optionally .gz).
    pub recording: PathBuf,
    /// Protocol: a built-in name (ricci2014) or a protocol TOML file.
    #[arg(long, default_value = DEFAULT_PROTOCOL_NAME)]
    pub protocol: String,
    /// Calibration file to write [default: <stem>.calibration.toml beside the recording].
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print the calibration as JSON instead of text tables.
    #[arg(long)]
    pub json: bool,
    /// Write the file, print nothing.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `acmw calibrate`.
pub fn run(args: CalibrateArgs) -> anyhow::Result<i32> {
    let protocol = Protocol::load(&args.protocol)?;
    let rec = Recording::read(&args.recording)?;
    let cal = calibrate(&rec, &protocol);
    let truth = simulate::load_truth_beside(&args.recording).transpose()?;
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.recording));
    cal.save(&output)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&cal)?)?;
    } else if !args.quiet {
        out!("{}", format_text(&cal, truth.as_ref()))?;
        outln!("wrote {}", output.display())?;
    }
    Ok(0)
}

/// The calibration as text: the rho table (the paper's Table 1), the residual
/// angles before and after the fit (its Figure 5), and the fit per IMU.
pub fn format_text(cal: &Calibration, truth: Option<&BTreeMap<String, Quat>>) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{}: {} samples, {:.1} s at {:.0} Hz; protocol {}",
        cal.recording, cal.samples, cal.duration_s, cal.rate_hz, cal.protocol
    );
    for w in &cal.warnings {
        let _ = writeln!(out, "warning: {w}");
    }
    let _ = writeln!(
        out,
        "\nReliability rho per movement and IMU (Ricci et al. 2014, Table 1)"
    );
    let w = cal
        .segments
        .iter()
        .map(|s| s.imu.len())
        .max()
        .unwrap_or(0)
        .max(7);
    let _ = write!(out, "{:<10}", "movement");
    for s in &cal.segments {
        let _ = write!(out, " {:>w$}", s.imu);
    }
    out.push('\n');
    for m in &cal.movements {
        let _ = write!(out, "{m:<10}");
        for s in &cal.segments {
            let cell = s
                .axis(m)
                .map_or("//".to_string(), |a| format!("{:.3}", a.rho));
            let cell = if s.missing.contains(m) {
                "missing".to_string()
            } else {
                cell
            };
            let _ = write!(out, " {cell:>w$}");
        }
        out.push('\n');
    }
    let _ = writeln!(
        out,
        "\nAngle between each functional axis and its estimate, deg (Figure 5):\nat the identity start, after the LM fit, and with TRIAD"
    );
    let _ = writeln!(
        out,
        "{:<w$} {:<9} {:>4} {:>6} {:>7} {:>6} {:>6}",
        "imu", "movement", "axis", "rho", "start", "LM", "TRIAD"
    );
    for s in &cal.segments {
        for a in &s.axes {
            let _ = writeln!(
                out,
                "{:<w$} {:<9} {:>4} {:>6.3} {:>7.1} {:>6.2} {:>6}",
                s.imu,
                a.movement,
                a.axis,
                a.rho,
                a.residual_before_deg,
                a.residual_lm_deg,
                a.residual_triad_deg
                    .map_or("-".to_string(), |t| format!("{t:.2}"))
            );
        }
    }
    let _ = writeln!(
        out,
        "\nRotation sensor -> functional frame per IMU (LM from the identity, damping 0.001, stop at 1e-4)"
    );
    let _ = write!(
        out,
        "{:<w$} {:>5} {:>10} {:>10} {:>7} {:>13}",
        "imu", "iter", "cost start", "cost end", "angle", "TRIAD pair"
    );
    let _ = write!(out, " {:>8}", "LM-TRIAD");
    if truth.is_some() {
        let _ = write!(out, " {:>8} {:>9}", "LM err", "TRIAD err");
    }
    out.push('\n');
    for s in &cal.segments {
        let _ = write!(
            out,
            "{:<w$} {:>5} {:>10.4} {:>10.4} {:>7.1} {:>13} {:>8}",
            s.imu,
            s.iterations,
            s.cost_start,
            s.cost_end,
            angle_deg(&s.rotation()),
            s.triad_movements.join("+"),
            s.lm_triad_deg
                .map_or("-".to_string(), |d| format!("{d:.2}"))
        );
        if let Some(t) = truth.and_then(|t| t.get(&s.imu)) {
            let triad = s.triad_rotation().map_or("-".to_string(), |q| {
                format!("{:.2}", angle_between_deg(&q, t))
            });
            let _ = write!(
                out,
                " {:>8.2} {:>9}",
                angle_between_deg(&s.rotation(), t),
                triad
            );
        }
        out.push('\n');
    }
    let n = cal.segments.len().max(1) as f64;
    let mean = cal
        .segments
        .iter()
        .map(|s| s.iterations as f64)
        .sum::<f64>()
        / n;
    let _ = writeln!(out, "mean LM iterations {mean:.1} (the paper: 6-9)");
    if truth.is_some() {
        let _ = writeln!(
            out,
            "(errors: angle to the true rotation in the simulation's truth beside the recording, deg)"
        );
    }
    for s in &cal.segments {
        if !s.missing.is_empty() {
            let _ = writeln!(out, "{}: missing {}", s.imu, s.missing.join(", "));
        }
    }
    for s in &cal.skipped {
        let _ = writeln!(out, "skipped {}: {}", s.imu, s.reason);
    }
    out
}

#[derive(Debug, Args)]
pub struct SimulateCalibrationArgs {
    /// Protocol: a built-in name (ricci2014) or a protocol TOML file.
    #[arg(long, default_value = DEFAULT_PROTOCOL_NAME)]
    pub protocol: String,
    /// Random seed (true rotations, sloppiness, noise).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Sampling rate, Hz.
    #[arg(long, default_value_t = 100.0)]
    pub rate: f64,
    /// RMS wobble of the functional movements' axes, degrees.
    #[arg(long, default_value_t = 20.0)]
    pub wobble: f64,
    /// Fixed deviation of each movement's mean axis, degrees.
    #[arg(long, default_value_t = 1.0)]
    pub bias: f64,
    /// One movement performed differently, LABEL:WOBBLE_DEG:BIAS_DEG (repeatable).
    #[arg(long = "sloppy", value_parser = parse_sloppy)]
    pub sloppy: Vec<(String, Sloppiness)>,
    /// Gyroscope noise per axis, deg/s RMS.
    #[arg(long, default_value_t = 1.0)]
    pub gyro_noise: f64,
    /// Accelerometer noise per axis, m/s^2 RMS.
    #[arg(long, default_value_t = 0.1)]
    pub acc_noise: f64,
    /// Round the readings to this many decimals, as a sensor's resolution
    /// [default: exact].
    #[arg(long)]
    pub decimals: Option<u32>,
    /// Output recording (`*.calib.csv`, optionally `.gz`); the truth goes beside
    /// it as `<stem>.truth.json`.
    #[arg(short, long)]
    pub output: PathBuf,
}

fn parse_sloppy(s: &str) -> Result<(String, Sloppiness), String> {
    let parts: Vec<&str> = s.split(':').collect();
    let [label, wobble, bias] = parts[..] else {
        return Err(format!("expected LABEL:WOBBLE_DEG:BIAS_DEG, found '{s}'"));
    };
    let num = |v: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|_| format!("'{v}' is not a number"))
    };
    Ok((
        label.trim().to_string(),
        Sloppiness {
            wobble_deg: num(wobble)?,
            bias_deg: num(bias)?,
        },
    ))
}

/// Runs `acmw simulate calibration`.
pub fn simulate_run(a: SimulateCalibrationArgs) -> anyhow::Result<i32> {
    let protocol = Protocol::load(&a.protocol)?;
    let defaults = CalibSimConfig::default();
    let config = CalibSimConfig {
        seed: a.seed,
        rate_hz: a.rate,
        gyro_noise_deg_s: a.gyro_noise,
        acc_noise: a.acc_noise,
        moving: Sloppiness {
            wobble_deg: a.wobble,
            bias_deg: a.bias,
        },
        overrides: a.sloppy.into_iter().collect(),
        ..defaults
    };
    let mut sim = match simulate::simulate(&protocol, &config) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("acmw: {e}");
            return Ok(2);
        }
    };
    if let Some(d) = a.decimals {
        sim.recording.round(d);
    }
    let text = sim.recording.to_csv();
    let bytes = if a
        .output
        .to_string_lossy()
        .to_ascii_lowercase()
        .ends_with(".gz")
    {
        use std::io::Write as _;
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(text.as_bytes())?;
        enc.finish()?
    } else {
        text.into_bytes()
    };
    if let Some(dir) = a.output.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    acm_workbench::save::atomic_write(&a.output, &bytes)
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", a.output.display()))?;
    let truth = simulate::truth_path(&a.output);
    acm_workbench::save::atomic_write(
        &truth,
        serde_json::to_string_pretty(&sim.config)?.as_bytes(),
    )
    .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", truth.display()))?;
    outln!(
        "{}: {} samples, {} IMUs, protocol {} (truth {})",
        a.output.display(),
        sim.recording.len(),
        sim.recording.imus.len(),
        protocol.name,
        truth.display()
    )?;
    Ok(0)
}
