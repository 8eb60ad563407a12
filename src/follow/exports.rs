//! Following a folder of Xsens MT Manager exports (one `.txt` per sensor)
//! while MT Manager appends to them: each export is read by its own
//! [`Tail`] (complete lines only), the rows are aligned on the packet
//! counter as the whole-folder reader aligns them
//! ([`GrowingExports`]), and a row is handed out once every sensor has
//! written past its packet.

use super::tail::{Tail, TailEvent};
use crate::model::Model;
use crate::trial::xsens_trial::{resolve, GrowingExports, XsensSource};
use crate::trial::{Trial, TrialError};
use std::path::{Path, PathBuf};

/// What one look at the folder found.
#[derive(Debug, Clone, PartialEq)]
pub enum ExportsEvent {
    /// No new row every sensor has.
    Nothing,
    /// New aligned rows (samples every sensor recorded, in counter order).
    Samples(Trial),
    /// An export was truncated, replaced, rewritten or removed, or the set
    /// of exports changed after rows were handed out: everything read is
    /// void and the next look reads every export from its start. (Exports
    /// that appear before the first row are taken in silently.)
    Restarted { reason: String },
}

/// The exports being followed.
struct Followed {
    source: XsensSource,
    tails: Vec<Tail>,
    rows: GrowingExports,
    /// Whether rows were handed out since the last start.
    handed_out: bool,
}

/// An incremental reader of a folder of exports being written.
pub struct ExportsTail {
    folder: PathBuf,
    model: Model,
    followed: Option<Followed>,
}

/// Whether `folder` holds the exports of a trial (as the whole-folder
/// reader resolves them) and every one has a complete header line: what
/// following it waits for (the IMU names, hence the model, are known then).
pub fn exports_ready(folder: &Path) -> bool {
    let Ok(source) = resolve(folder) else {
        return false;
    };
    source.files.iter().all(|(f, _)| {
        let Ok(bytes) = crate::input::read_bytes(f) else {
            return false;
        };
        String::from_utf8_lossy(&bytes)
            .split_inclusive('\n')
            .any(|l| {
                let t = l.trim_start_matches('\u{feff}').trim();
                l.ends_with('\n') && !t.is_empty() && !t.starts_with("//")
            })
    })
}

impl ExportsTail {
    /// A reader of the exports in `folder`, their IMUs named through
    /// `model`'s aliases; nothing read yet.
    pub fn new(folder: &Path, model: &Model) -> ExportsTail {
        ExportsTail {
            folder: folder.to_path_buf(),
            model: model.clone(),
            followed: None,
        }
    }

    /// Bytes read so far, over every export.
    pub fn offset(&self) -> u64 {
        self.followed
            .as_ref()
            .map_or(0, |f| f.tails.iter().map(Tail::offset).sum())
    }

    /// Whether every export was read to its end as it is on disk now, with
    /// no partial line waiting, and the folder still holds those exports:
    /// the rows read are the whole trial.
    pub fn read_whole(&self) -> bool {
        let Some(f) = &self.followed else {
            return false;
        };
        let same = resolve(&self.folder).is_ok_and(|s| same_exports(&s, &f.source));
        same && f.tails.iter().zip(&f.source.files).all(|(t, (p, _))| {
            !t.has_partial_line() && std::fs::metadata(p).is_ok_and(|m| m.len() == t.offset())
        })
    }

    fn restart(&mut self, reason: String) -> ExportsEvent {
        self.followed = None;
        ExportsEvent::Restarted { reason }
    }

    /// Looks at every export once: the rows every sensor has written since
    /// the last look, or that it restarted. Before the folder holds exports
    /// (or, with a mapping, every export it names) this is
    /// [`ExportsEvent::Nothing`]. Errors are located in the export at fault.
    pub fn poll(&mut self) -> Result<ExportsEvent, TrialError> {
        let source = match resolve(&self.folder) {
            Ok(s) => s,
            Err(e) if self.followed.is_some() => {
                return Ok(self.restart(format!("no longer holds the exports read ({e})")));
            }
            Err(_) => return Ok(ExportsEvent::Nothing),
        };
        if let Some(f) = &self.followed {
            if !same_exports(&source, &f.source) && !f.handed_out {
                // Exports still appearing (MT Manager starts them one by
                // one; without a mapping a file counts once it starts like
                // an export): nothing was handed out, so nothing is void.
                self.followed = None;
            }
        }
        if let Some(f) = &self.followed {
            if !same_exports(&source, &f.source) {
                let names: Vec<String> = source.files.iter().map(|(p, _)| file_name(p)).collect();
                return Ok(self.restart(format!("has other exports now ({})", names.join(", "))));
            }
        }
        if self.followed.is_none() {
            let rows = GrowingExports::new(&self.folder, &source, &self.model)?;
            let tails = source.files.iter().map(|(p, _)| Tail::new(p)).collect();
            self.followed = Some(Followed {
                source,
                tails,
                rows,
                handed_out: false,
            });
        }
        let Some(f) = self.followed.as_mut() else {
            return Ok(ExportsEvent::Nothing);
        };
        for k in 0..f.tails.len() {
            let event = f.tails[k].poll().map_err(|e| {
                TrialError::file(f.source.files[k].0.display().to_string(), e.to_string())
            })?;
            match event {
                TailEvent::Nothing => {}
                TailEvent::Lines { text, first_line } => {
                    f.rows.push_lines(k, &text, first_line)?;
                }
                TailEvent::Restarted { reason } => {
                    let name = file_name(&f.source.files[k].0);
                    return Ok(self.restart(format!("export {name} {reason}")));
                }
            }
        }
        Ok(match f.rows.aligned()? {
            Some(t) => {
                f.handed_out = true;
                ExportsEvent::Samples(t)
            }
            None => ExportsEvent::Nothing,
        })
    }
}

/// The same export files, IMU names and mapping.
fn same_exports(a: &XsensSource, b: &XsensSource) -> bool {
    a.files == b.files && a.mapping_text == b.mapping_text
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trial::xsens_trial::read_xsens_trial;
    use rand::{Rng, SeedableRng};
    use std::fmt::Write as _;
    use std::io::Write as _;

    /// Exports of `trial` without an `Update Rate` comment (the rate comes
    /// from `SampleTimeFine`), semicolon-separated with decimal commas for
    /// the second sensor, counters wrapping, sensors starting and ending
    /// apart, the first sensor missing two packets. No mapping: each
    /// sensor is named by its file name's serial (the IMU's name).
    fn exports(trial: &Trial) -> Vec<(String, String)> {
        let n = trial.len() as u64;
        let first_packet = 65_500u64;
        trial
            .imus
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let semi = k == 1;
                let sep = if semi { ";" } else { "\t" };
                let num = |v: f64| {
                    let t = v.to_string();
                    if semi {
                        t.replace('.', ",")
                    } else {
                        t
                    }
                };
                let mut text = String::from("// Filter Profile: human (46.1)\n");
                let mut head = vec!["PacketCounter", "SampleTimeFine", "Quat_q0", "Quat_q1"];
                head.extend(["Quat_q2", "Quat_q3"]);
                text.push_str(&head.join(sep));
                text.push('\n');
                let first = first_packet - (k as u64 % 3);
                let last = first_packet + n - 1 + (k as u64 % 2);
                for c in first..=last {
                    if k == 0 && (first_packet + 50..first_packet + 52).contains(&c) {
                        continue;
                    }
                    let i = (c.clamp(first_packet, first_packet + n - 1) - first_packet) as usize;
                    let q = s.orientation[i];
                    let cells = [c as f64 * 200.0, q.w, q.i, q.j, q.k].map(num);
                    let _ = writeln!(text, "{:05}{sep}{}", c % 65_536, cells.join(sep));
                }
                (format!("rec_{}.txt", s.name.replace('_', "-")), text)
            })
            .collect()
    }

    #[test]
    fn rows_aligned_as_they_grow_are_the_trial_the_folder_reader_reads() {
        let sim = crate::simulate::simulate(&crate::simulate::SimConfig {
            duration_s: 6.0,
            ..crate::simulate::SimConfig::full_body(4)
        })
        .unwrap();
        let mut small = sim.trial.clone();
        small.imus.truncate(3);
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("rec");
        std::fs::create_dir_all(&folder).unwrap();
        let texts = exports(&small);
        let model = Model::infant13();
        // Serial-named IMUs (base, pelvis, ...) through a model that knows them.
        let mut x = ExportsTail::new(&folder, &model);
        assert_eq!(x.poll().unwrap(), ExportsEvent::Nothing);
        let mut files: Vec<std::fs::File> = texts
            .iter()
            .map(|(name, _)| std::fs::File::create(folder.join(name)).unwrap())
            .collect();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut pos = vec![0usize; texts.len()];
        let mut got: Option<Trial> = None;
        let mut batches = 0;
        loop {
            let open: Vec<usize> = (0..texts.len())
                .filter(|&k| pos[k] < texts[k].1.len())
                .collect();
            if open.is_empty() {
                break;
            }
            let k = open[rng.random_range(0..open.len())];
            let bytes = texts[k].1.as_bytes();
            let n = rng.random_range(1..300).min(bytes.len() - pos[k]);
            files[k].write_all(&bytes[pos[k]..pos[k] + n]).unwrap();
            pos[k] += n;
            match x.poll().unwrap() {
                ExportsEvent::Nothing => {}
                ExportsEvent::Samples(b) => {
                    batches += 1;
                    match &mut got {
                        None => got = Some(b),
                        Some(t) => {
                            t.time_s.extend(b.time_s);
                            for (s, bs) in t.imus.iter_mut().zip(b.imus) {
                                assert_eq!(s.name, bs.name);
                                s.orientation.extend(bs.orientation);
                            }
                        }
                    }
                }
                e => panic!("{e:?}"),
            }
        }
        assert!(x.read_whole());
        let whole = read_xsens_trial(&folder, &model).unwrap();
        let got = got.unwrap();
        assert!(batches > 10, "{batches}");
        // Packets 50 and 51 are left out of every sensor.
        assert_eq!(whole.len(), small.len() - 2);
        assert_eq!(got.time_s, whole.time_s);
        assert_eq!(got.imus, whole.imus);
        assert_eq!(got.name, "rec");
        // A bad cell is located in its export.
        let bad = format!("{:05}\t1\t2\t0\t0\t0\n", 1000);
        files[0].write_all(bad.as_bytes()).unwrap();
        let e = x.poll().unwrap_err().to_string();
        let line = texts[0].1.lines().count() + 1;
        assert!(
            e.contains(&format!("{}:{line}:3:", texts[0].0)) && e.contains("unit quaternion"),
            "{e}"
        );
        // Another export appearing after rows were handed out starts the
        // folder over.
        std::fs::write(folder.join(&texts[0].0), &texts[0].1).unwrap();
        let mut x = ExportsTail::new(&folder, &model);
        assert!(matches!(x.poll().unwrap(), ExportsEvent::Samples(_)));
        std::fs::write(folder.join("rec_other.txt"), &texts[2].1).unwrap();
        let ExportsEvent::Restarted { reason } = x.poll().unwrap() else {
            panic!("a new export was not noticed");
        };
        assert!(reason.contains("rec_other.txt"), "{reason}");
    }
}
