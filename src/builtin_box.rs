//! The limit boxes of the built-in Table 3-2 (`joint_limits/table_3_2.csv`):
//! `[lower, upper]` per axis X, Y, Z in degrees, by joint name or kind, read
//! from the CSV the program ships. What `Joint::limit_box` reads to pick, of a
//! rotation's two Z-Y-X triplets, the one the joint's table reads
//! (docs/method.md section 2.5); the limits module parses the same text into
//! full tables (its tests hold the two equal).

use std::sync::OnceLock;

/// The built-in Table 3-2's CSV text.
const TABLE_3_2: &str = include_str!("../joint_limits/table_3_2.csv");

/// One row: joint or kind, axis index (0 = X), lower, upper (degrees).
type Row = (String, usize, f64, f64);

fn rows() -> &'static [Row] {
    static ROWS: OnceLock<Vec<Row>> = OnceLock::new();
    ROWS.get_or_init(|| {
        TABLE_3_2
            .lines()
            .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
            .skip(1)
            .filter_map(|l| {
                let f: Vec<&str> = l.split(',').map(str::trim).collect();
                let axis = match *f.get(1)? {
                    "X" | "x" => 0,
                    "Y" | "y" => 1,
                    "Z" | "z" => 2,
                    _ => return None,
                };
                Some((
                    f.first()?.to_string(),
                    axis,
                    f.get(3)?.parse().ok()?,
                    f.get(4)?.parse().ok()?,
                ))
            })
            .collect()
    })
}

/// The box of joint `joint` (its own rows, else those of its `kind`) in the
/// built-in Table 3-2, degrees; `None` when an axis has no row.
pub fn table_3_2_box(joint: &str, kind: &str) -> Option<[[f64; 2]; 3]> {
    let find = |name: &str, axis: usize| {
        rows()
            .iter()
            .find(|r| r.0 == name && r.1 == axis)
            .map(|r| [r.2, r.3])
    };
    let row = |axis: usize| find(joint, axis).or_else(|| find(kind, axis));
    Some([row(0)?, row(1)?, row(2)?])
}
