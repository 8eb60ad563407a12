//! When a growing trial is solved again.

/// The solve points of a growing trial, seconds of trial time from its
/// first sample: every `warmup_s` while the first window fills (none when
/// `warmup_s` is 0 or not below `window_s`), then `window_s + k * hop_s` for
/// k = 0, 1, ...: the moments window `[k * hop, k * hop + window)` of the
/// drift layout is complete. A solve at point `p` corrects the samples
/// before `p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Schedule {
    /// Drift window length, seconds.
    pub window_s: f64,
    /// Hop between windows, seconds.
    pub hop_s: f64,
    /// Interval of the solves before the first window is complete, seconds.
    pub warmup_s: f64,
}

impl Schedule {
    /// Number of warm-up points (before the first window is complete).
    fn warmups(&self) -> usize {
        if self.warmup_s > 0.0 && self.warmup_s < self.window_s {
            // Points k * warmup_s < window_s, k >= 1.
            ((self.window_s / self.warmup_s).ceil() as usize).saturating_sub(1)
        } else {
            0
        }
    }

    /// The `k`-th solve point (k = 0, 1, ...), seconds from the first sample.
    pub fn point(&self, k: usize) -> f64 {
        let w = self.warmups();
        if k < w {
            (k + 1) as f64 * self.warmup_s
        } else {
            self.window_s + (k - w) as f64 * self.hop_s
        }
    }

    /// The index of the last point at or before `elapsed_s` (seconds from the
    /// first sample), if any.
    pub fn last_reached(&self, elapsed_s: f64) -> Option<usize> {
        if elapsed_s.is_nan() || elapsed_s < self.point(0) {
            return None;
        }
        let w = self.warmups();
        let mut k = if elapsed_s < self.window_s {
            ((elapsed_s / self.warmup_s).floor() as usize).clamp(1, w.max(1)) - 1
        } else {
            w + ((elapsed_s - self.window_s) / self.hop_s).floor() as usize
        };
        // The divisions above may round either way: settle on the exact point.
        while self.point(k + 1) <= elapsed_s {
            k += 1;
        }
        while k > 0 && self.point(k) > elapsed_s {
            k -= 1;
        }
        Some(k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_warm_up_then_follow_the_windows() {
        let s = Schedule {
            window_s: 60.0,
            hop_s: 30.0,
            warmup_s: 10.0,
        };
        let p: Vec<f64> = (0..8).map(|k| s.point(k)).collect();
        assert_eq!(p, [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 90.0, 120.0]);
        assert_eq!(s.last_reached(9.99), None);
        assert_eq!(s.last_reached(10.0), Some(0));
        assert_eq!(s.last_reached(59.9), Some(4));
        assert_eq!(s.last_reached(60.0), Some(5));
        assert_eq!(s.last_reached(119.0), Some(6));
        assert_eq!(s.last_reached(121.0), Some(7));
        for k in 0..20 {
            assert_eq!(s.last_reached(s.point(k)), Some(k));
            assert_eq!(s.last_reached(s.point(k) + 1e-6), Some(k));
        }
        let none = Schedule { warmup_s: 0.0, ..s };
        assert_eq!(none.point(0), 60.0);
        assert_eq!(none.last_reached(59.0), None);
        assert_eq!(none.last_reached(95.0), Some(1));
    }
}
