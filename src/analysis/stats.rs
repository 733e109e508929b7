//! Running statistics of deviations, updated per point as a scan streams in, mergeable across profiles and
//! instances, and the tolerance verdicts built on them.

use serde::{Deserialize, Serialize};

pub use crate::api::{DeviationStats, Verdict};

/// Running statistics of deviations, updated per point.
///
/// The mean comes from a compensated (Neumaier) sum, so 10^5 deviations of 0.8 mm average to the last bit; the
/// spread from Welford's update, which never subtracts two large sums of squares.
#[derive(Debug, Clone, Default)]
pub struct RunningStats {
    count: usize,
    sum: f64,
    /// The low-order part of `sum` that its rounding lost.
    compensation: f64,
    /// Welford's running mean and sum of squared differences from it.
    welford_mean: f64,
    squared_spread: f64,
    min: f64,
    max: f64,
    worst: f64,
    worst_at: [f64; 3],
}

impl RunningStats {
    /// Adds one finite deviation measured at `at` (machine frame, mm). Of equally large deviations the first
    /// stays the worst.
    pub fn push(&mut self, deviation_mm: f64, at: [f64; 3]) {
        debug_assert!(
            deviation_mm.is_finite(),
            "deviation {deviation_mm} is not finite"
        );
        if self.count == 0 {
            (self.min, self.max) = (deviation_mm, deviation_mm);
            (self.worst, self.worst_at) = (deviation_mm, at);
        } else {
            self.min = self.min.min(deviation_mm);
            self.max = self.max.max(deviation_mm);
            if deviation_mm.abs() > self.worst.abs() {
                (self.worst, self.worst_at) = (deviation_mm, at);
            }
        }
        self.count += 1;
        self.add_to_sum(deviation_mm);
        let delta = deviation_mm - self.welford_mean;
        self.welford_mean += delta / self.count as f64;
        self.squared_spread += delta * (deviation_mm - self.welford_mean);
    }

    /// Adds every deviation of `other`, as if they had been pushed here after this one's.
    pub fn merge(&mut self, other: &RunningStats) {
        if other.count == 0 {
            return;
        }
        if self.count == 0 {
            *self = other.clone();
            return;
        }
        let (mine, theirs) = (self.count as f64, other.count as f64);
        let total = mine + theirs;
        // Chan, Golub and LeVeque's pairwise update of Welford's moments.
        let delta = other.welford_mean - self.welford_mean;
        self.welford_mean += delta * theirs / total;
        self.squared_spread += other.squared_spread + delta * delta * mine * theirs / total;
        self.add_to_sum(other.sum);
        self.compensation += other.compensation;
        self.count += other.count;
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
        if other.worst.abs() > self.worst.abs() {
            (self.worst, self.worst_at) = (other.worst, other.worst_at);
        }
    }

    /// The summary, `None` before the first point.
    pub fn summary(&self) -> Option<DeviationStats> {
        if self.count == 0 {
            return None;
        }
        let n = self.count as f64;
        let mean = (self.sum + self.compensation) / n;
        let variance = (self.squared_spread / n).max(0.0);
        Some(DeviationStats {
            points: self.count,
            mean_mm: mean,
            rms_mm: (mean * mean + variance).sqrt(),
            std_mm: variance.sqrt(),
            min_mm: self.min,
            max_mm: self.max,
            worst_mm: self.worst,
            worst_at_mm: self.worst_at,
        })
    }

    pub fn count(&self) -> usize {
        self.count
    }

    /// Neumaier's compensated addition.
    fn add_to_sum(&mut self, value: f64) {
        let total = self.sum + value;
        self.compensation += if self.sum.abs() >= value.abs() {
            (self.sum - total) + value
        } else {
            (value - total) + self.sum
        };
        self.sum = total;
    }
}

/// The band a deviation must lie in, mm (e.g. -0.1 .. +0.1), bounds included.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tolerance {
    pub lower_mm: f64,
    pub upper_mm: f64,
}

impl Tolerance {
    /// The verdict on deviations summarised by `stats`, of which `points_outside` failed [`Tolerance::contains`]
    /// (counted as they arrived).
    pub fn verdict(&self, stats: &DeviationStats, points_outside: usize) -> Verdict {
        if points_outside == 0 {
            Verdict::Pass
        } else {
            Verdict::Fail {
                points_outside,
                worst_mm: stats.worst_mm,
                parameters_outside: 0,
            }
        }
    }

    pub fn contains(&self, d: f64) -> bool {
        self.lower_mm <= d && d <= self.upper_mm
    }
}

#[cfg(test)]
mod tests;
