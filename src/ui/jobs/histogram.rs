//! The histogram screen's jobs: histograms and centroids over a span, and
//! writing a suggested or centroid table.

use crate::analysis::centroid::centroids;
use crate::analysis::histogram::{histograms, DEFAULT_BIN_DEG};
use crate::analysis::suggest::{same_file, WriteError};
use crate::analysis::{pool_by_joint, pool_by_table_row, TimeSpan, TrialRef};
use crate::limits::LimitTable;
use crate::ui::msg::{Computed, Msg, RowAnalysis};
use crate::ui::workbench::Loaded;
use std::path::Path;
use std::sync::Arc;

/// Histograms (per joint and per table row) and centroids of loaded trials
/// over `span` (in a worker thread).
pub fn compute_job(trials: &[Arc<Loaded>], span: TimeSpan, table: &LimitTable) -> Msg {
    let refs: Vec<TrialRef> = trials
        .iter()
        .map(|l| TrialRef {
            trial: &l.trial,
            model: &l.model,
        })
        .collect();
    let (joints, hists, centroid_table) = match refs.first() {
        None => (vec![], vec![], centroids(&[], span)),
        Some(r) => {
            let by_row = pool_by_table_row(&refs, span, table);
            (
                histograms(&pool_by_joint(&refs, span), table, r.model, DEFAULT_BIN_DEG),
                histograms(&by_row, table, r.model, DEFAULT_BIN_DEG),
                centroids(&by_row, span),
            )
        }
    };
    Msg::Histograms(Box::new(Computed {
        span,
        joints,
        rows: Arc::new(RowAnalysis {
            table: table.clone(),
            hists,
            centroids: centroid_table,
        }),
    }))
}

/// Writes a table (the work behind [`Effect::WriteTable`]): creates the
/// folder, saves atomically keeping `.bak`, never over `original`.
pub fn write_job(path: &Path, original: Option<&Path>, csv: &str) -> Msg {
    let result = (|| {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        if let Some(orig) = original.filter(|o| same_file(path, o)) {
            return Err(WriteError::Original(orig.to_path_buf()).to_string());
        }
        crate::save::atomic_write(path, csv.as_bytes())
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(path.display().to_string())
    })();
    Msg::TableWritten(result)
}
