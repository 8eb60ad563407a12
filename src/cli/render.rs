//! `acmw render`: print a workbench screen as text, through the same drawing
//! code as the terminal (and the snapshot tests).

use acm_workbench::acm::Variant;
use acm_workbench::ui::headless::{
    buffer_ansi, buffer_text, draw, load_app_with, show, Show, SCREENS,
};
use acm_workbench::ui::theme::Theme;
use anyhow::anyhow;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Screen: trials, trial, compare, limits, help, calibration, histogram, scatter, globe,
    /// applied, stick or heading.
    #[arg(value_parser = SCREENS)]
    pub screen: String,
    /// Folder of trials [default: ./sample_trials].
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// Folder of limit tables and settings.toml [default: ./joint_limits].
    #[arg(long, value_name = "DIR")]
    pub limits_dir: Option<PathBuf>,
    /// Body model to read the trials with (built-in name or TOML file)
    /// [default: per trial, the built-in model that knows most of its IMUs].
    #[arg(long)]
    pub model: Option<String>,
    /// Trial file name inside the folder [default: the first readable one].
    #[arg(long)]
    pub trial: Option<String>,
    /// Joint to show on the trial screen [default: the first].
    #[arg(long)]
    pub joint: Option<String>,
    /// Variant to show [default: drift].
    #[arg(long, value_parser = super::common::variant_parser())]
    pub variant: Option<Variant>,
    /// Size in cells, WxH.
    #[arg(long, default_value = "80x24", value_parser = parse_size)]
    pub size: (u16, u16),
    /// Emit ANSI colour codes (SGR) per cell.
    #[arg(long)]
    pub color: bool,
}

pub fn parse_size(s: &str) -> Result<(u16, u16), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH, found '{s}'"))?;
    let n = |v: &str| v.trim().parse::<u16>().map_err(|e| format!("'{v}': {e}"));
    Ok((n(w)?, n(h)?))
}

pub fn run(a: RenderArgs, theme: &str, ascii: bool) -> anyhow::Result<i32> {
    let dir = a.dir.unwrap_or_else(|| PathBuf::from("sample_trials"));
    let no_color = std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty());
    let theme = Theme::builtin(theme, no_color)
        .map_err(|e| anyhow!(e))?
        .with_ascii(ascii);
    let limits_dir = a
        .limits_dir
        .unwrap_or_else(super::common::default_limits_dir);
    // Read here, not by the workbench: a malformed table is a located error
    // with exit code 3.
    let read = acm_workbench::limits::LimitsDir::load(&limits_dir)?;
    let limits = acm_workbench::ui::jobs::limits_state(&limits_dir, read);
    let model = a
        .model
        .as_deref()
        .map(acm_workbench::model::Model::load)
        .transpose()?;
    let label = dir.display().to_string();
    let mut app = load_app_with(&label, &dir, limits, model).map_err(|e| anyhow!(e))?;
    show(
        &mut app,
        &Show {
            screen: a.screen,
            trial: a.trial,
            joint: a.joint,
            variant: a.variant,
        },
    )
    .map_err(|e| anyhow!(e))?;
    let buf = draw(&app, &theme, a.size.0, a.size.1);
    let text = if a.color {
        buffer_ansi(&buf)
    } else {
        buffer_text(&buf)
    };
    out!("{text}")?;
    Ok(super::EXIT_OK)
}
