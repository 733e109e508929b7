//! Motion with speed and acceleration limits: trapezoidal velocity profiles (a triangle when the move is too
//! short to reach full speed), and the trajectory of the probe centre over machine time in seconds.

use nalgebra::Point3;

/// Speed (mm/s) and acceleration (mm/s^2) of a move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    pub speed: f64,
    pub accel: f64,
}

impl Limits {
    /// Time to travel `distance` from rest to rest.
    pub fn duration(&self, distance: f64) -> f64 {
        if distance <= 0.0 {
            return 0.0;
        }
        let ramp_distance = self.speed * self.speed / self.accel;
        if distance >= ramp_distance {
            distance / self.speed + self.speed / self.accel
        } else {
            2.0 * (distance / self.accel).sqrt()
        }
    }

    /// Distance covered `t` seconds into a rest-to-rest move of `distance`.
    pub fn travelled(&self, distance: f64, t: f64) -> f64 {
        let total = self.duration(distance);
        if t <= 0.0 {
            return 0.0;
        }
        if t >= total {
            return distance;
        }
        // Peak speed: the limit, or lower on a triangular profile.
        let peak = self.speed.min((distance * self.accel).sqrt());
        let ramp = peak / self.accel;
        if t < ramp {
            0.5 * self.accel * t * t
        } else if t <= total - ramp {
            0.5 * peak * ramp + peak * (t - ramp)
        } else {
            let left = total - t;
            distance - 0.5 * self.accel * left * left
        }
    }
}

/// Samples per rest-to-rest move: enough that the position between samples (a straight line either way)
/// is exact and its timing within a percent of the profile.
const SAMPLES_PER_MOVE: usize = 32;

/// Where the probe centre is over time: piecewise linear between samples `(t, position)`, t ascending from 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    samples: Vec<(f64, Point3<f64>)>,
}

impl Trajectory {
    /// Standing at `start`.
    pub fn at(start: Point3<f64>) -> Self {
        Trajectory {
            samples: vec![(0.0, start)],
        }
    }

    pub fn end(&self) -> Point3<f64> {
        self.samples.last().expect("never empty").1
    }

    pub fn duration(&self) -> f64 {
        self.samples.last().expect("never empty").0
    }

    /// A straight rest-to-rest move to `to`.
    pub fn move_to(&mut self, to: Point3<f64>, limits: Limits) {
        self.follow(&[self.end(), to], limits);
    }

    /// Through `path` (its first point should be the current end) as one motion: accelerating at the start,
    /// braking at the end, the profile applied to the arc length. Returns each path point's time.
    pub fn follow(&mut self, path: &[Point3<f64>], limits: Limits) -> Vec<f64> {
        let (t0, start) = *self.samples.last().expect("never empty");
        let mut arc = Vec::with_capacity(path.len());
        let mut length = 0.0;
        let mut previous = start;
        for p in path {
            length += (p - previous).norm();
            arc.push(length);
            previous = *p;
        }
        let total = limits.duration(length);
        let times: Vec<f64> = arc
            .iter()
            .map(|s| t0 + time_at_distance(limits, length, *s, total))
            .collect();
        if path.len() <= 2 && length > 0.0 {
            // A single segment: sample the profile so that positions between samples keep its timing.
            let from = start;
            let to = *path.last().expect("two points");
            for i in 1..=SAMPLES_PER_MOVE {
                let t = total * i as f64 / SAMPLES_PER_MOVE as f64;
                let fraction = limits.travelled(length, t) / length;
                self.samples.push((t0 + t, from + (to - from) * fraction));
            }
        } else {
            for (p, t) in path.iter().zip(&times) {
                self.samples.push((*t, *p));
            }
        }
        times
    }

    /// The position at time `t`.
    pub fn position(&self, t: f64) -> Point3<f64> {
        let after = self.samples.partition_point(|(ts, _)| *ts <= t);
        if after == 0 {
            return self.samples[0].1;
        }
        if after == self.samples.len() {
            return self.end();
        }
        let (t0, p0) = self.samples[after - 1];
        let (t1, p1) = self.samples[after];
        if t1 <= t0 {
            return p1;
        }
        p0 + (p1 - p0) * ((t - t0) / (t1 - t0))
    }
}

/// Inverse of [`Limits::travelled`] by bisection: the time at which `s` of `length` is covered.
fn time_at_distance(limits: Limits, length: f64, s: f64, total: f64) -> f64 {
    if s >= length {
        // Braking ends on a parabola's vertex, too flat for bisection to land exactly.
        return total;
    }
    let (mut lo, mut hi) = (0.0, total);
    for _ in 0..50 {
        let mid = (lo + hi) / 2.0;
        if limits.travelled(length, mid) < s {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIMITS: Limits = Limits {
        speed: 100.0,
        accel: 1000.0,
    };

    #[test]
    fn long_moves_are_trapezoids_and_short_ones_triangles() {
        // 100 mm at 100 mm/s with 0.1 s ramps: 1 s cruise-equivalent plus one ramp.
        assert!((LIMITS.duration(100.0) - 1.1).abs() < 1e-12);
        // 1 mm never reaches full speed: 2 sqrt(1/1000).
        assert!((LIMITS.duration(1.0) - 2.0 * 0.001f64.sqrt()).abs() < 1e-12);
        assert_eq!(LIMITS.duration(0.0), 0.0);
        for distance in [1.0, 10.0, 100.0] {
            let total = LIMITS.duration(distance);
            assert!((LIMITS.travelled(distance, total / 2.0) - distance / 2.0).abs() < 1e-9);
            assert_eq!(LIMITS.travelled(distance, total), distance);
        }
    }

    #[test]
    fn a_trajectory_interpolates_its_moves() {
        let mut trajectory = Trajectory::at(Point3::origin());
        trajectory.move_to(Point3::new(100.0, 0.0, 0.0), LIMITS);
        assert!((trajectory.duration() - 1.1).abs() < 1e-9);
        assert!((trajectory.position(0.55).x - 50.0).abs() < 0.5);
        assert_eq!(trajectory.position(1.3), Point3::new(100.0, 0.0, 0.0));
        let times = trajectory.follow(
            &[
                Point3::new(100.0, 0.0, 0.0),
                Point3::new(100.0, 50.0, 0.0),
                Point3::new(100.0, 100.0, 0.0),
            ],
            LIMITS,
        );
        assert!((times[2] - 2.2).abs() < 1e-9, "{times:?}");
        assert!((times[1] - 1.65).abs() < 1e-9);
    }
}
