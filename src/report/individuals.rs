//! The individuals (X) control chart of one value per part, in the order inspected: centre line the mean, control
//! limits the mean +- 2.66 times the mean moving range (2.66 = 3 / d2, d2 = 1.128 for ranges of two consecutive
//! parts), and the parts that break the Western Electric rules checked here.

/// Western Electric rule 4: this many consecutive parts on one side of the centre line signal a shift.
pub const RUN_LENGTH: usize = 8;

/// 3 / d2 for moving ranges of two (d2 = 1.128): the control limits' distance from the centre in mean moving ranges.
const LIMIT_FACTOR: f64 = 2.66;

/// Why a part's value signals that the process is not in statistical control.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    /// Above the upper or below the lower control limit (rule 1).
    BeyondLimits,
    /// The [`RUN_LENGTH`]-th or a later part of a run on one side of the centre line (rule 4).
    RunOnOneSide,
}

impl Rule {
    pub fn describe(self) -> &'static str {
        match self {
            Rule::BeyondLimits => "beyond a control limit",
            Rule::RunOnOneSide => "8 or more in a row on one side of the centre",
        }
    }
}

/// The chart of a run of values.
#[derive(Debug, Clone, PartialEq)]
pub struct Individuals {
    pub centre: f64,
    pub mean_moving_range: f64,
    pub upper_limit: f64,
    pub lower_limit: f64,
    /// (index into the run, rule) for each signal, in the order of the run; a part can break both rules.
    pub signals: Vec<(usize, Rule)>,
}

/// The chart of `values`; `None` for fewer than two, which have no moving range.
pub fn individuals(values: &[f64]) -> Option<Individuals> {
    if values.len() < 2 {
        return None;
    }
    let centre = values.iter().sum::<f64>() / values.len() as f64;
    let mean_moving_range =
        values.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f64>() / (values.len() - 1) as f64;
    let upper_limit = centre + LIMIT_FACTOR * mean_moving_range;
    let lower_limit = centre - LIMIT_FACTOR * mean_moving_range;
    let mut signals = Vec::new();
    // The run so far: its side of the centre (-1, 0 on the line, +1) and its length.
    let (mut side, mut run) = (0.0, 0);
    for (k, &value) in values.iter().enumerate() {
        if value > upper_limit || value < lower_limit {
            signals.push((k, Rule::BeyondLimits));
        }
        let here = if value == centre {
            0.0
        } else {
            (value - centre).signum()
        };
        run = if here != 0.0 && here == side {
            run + 1
        } else {
            1
        };
        side = here;
        if side != 0.0 && run >= RUN_LENGTH {
            signals.push((k, Rule::RunOnOneSide));
        }
    }
    Some(Individuals {
        centre,
        mean_moving_range,
        upper_limit,
        lower_limit,
        signals,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_from_the_mean_moving_range() {
        // Moving ranges 1, 2, 1, 7: mean 2.75. Centre 20 / 5 = 4; limits 4 +- 2.66 x 2.75 = 4 +- 7.315.
        let chart = individuals(&[1.0, 2.0, 4.0, 3.0, 10.0]).unwrap();
        assert!((chart.centre - 4.0).abs() < 1e-12);
        assert!((chart.mean_moving_range - 2.75).abs() < 1e-12);
        assert!((chart.upper_limit - 11.315).abs() < 1e-12);
        assert!((chart.lower_limit + 3.315).abs() < 1e-12);
        assert!(chart.signals.is_empty(), "{:?}", chart.signals);
    }

    #[test]
    fn a_jump_and_a_long_run_are_signalled() {
        // Ten parts at 0 then one at 1: moving ranges sum to 1 over 10, mean 0.1; centre 1/11 = 0.0909, upper
        // limit 0.0909 + 0.266 = 0.357, so the last part is beyond it. The ten below the centre form a run: the
        // 8th, 9th and 10th (indices 7, 8, 9) signal.
        let mut values = vec![0.0; 10];
        values.push(1.0);
        let chart = individuals(&values).unwrap();
        assert!((chart.upper_limit - (1.0 / 11.0 + 0.266)).abs() < 1e-12);
        assert_eq!(
            chart.signals,
            [
                (7, Rule::RunOnOneSide),
                (8, Rule::RunOnOneSide),
                (9, Rule::RunOnOneSide),
                (10, Rule::BeyondLimits)
            ]
        );
    }

    #[test]
    fn a_run_is_broken_by_a_part_on_the_other_side() {
        let mut values = vec![1.0; 7];
        values.push(-1.0);
        values.extend([1.0; 7]);
        let chart = individuals(&values).unwrap();
        assert!(
            chart.signals.iter().all(|(_, r)| *r != Rule::RunOnOneSide),
            "{:?}",
            chart.signals
        );
        assert_eq!(individuals(&[0.5]), None, "one part has no moving range");
    }
}
