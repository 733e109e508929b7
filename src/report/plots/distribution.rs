//! The thickness and camber of one profile's sections along the chord, measured against nominal: per instance,
//! the measured thickness (the inscribed circle's diameter) and camber (the mean line's distance from its chord
//! line) minus the nominal's at the same place along the chord, in two panels. Differences, not the values: a
//! 20 mm thick section a few microns thin would not show beside its nominal.

use plotters::prelude::*;

use super::{InstanceSection, PlotError};
use crate::analysis::section::SectionDistribution;

const WIDTH: u32 = 1080;
const HEIGHT: u32 = 380;
const FIGURE: &str = "thickness and camber";
/// Room above and below the data, as a share of its span.
const PADDING: f64 = 0.08;
/// The span shown when every difference is the same, mm.
const SMALLEST_SPAN_MM: f64 = 0.001;

/// Which of a station's values a panel shows.
#[derive(Debug, Clone, Copy)]
enum Quantity {
    Thickness = 1,
    Camber = 2,
}

/// The figure of profile `name`, `None` when no instance's section has a distribution.
pub fn distribution_svg(
    name: &str,
    sections: &[InstanceSection],
) -> Result<Option<String>, PlotError> {
    if sections.iter().all(|s| s.distribution.is_none()) {
        return Ok(None);
    }
    let failed = PlotError::drawing(name, FIGURE);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(&failed)?;
        let title = format!("{name}: measured minus nominal along the chord (mm)");
        let body = root.titled(&title, ("sans-serif", 18)).map_err(&failed)?;
        let (left, right) = body.split_horizontally(WIDTH / 2);
        for (area, quantity, label) in [
            (
                &left,
                Quantity::Thickness,
                "thickness (inscribed circle) (mm)",
            ),
            (
                &right,
                Quantity::Camber,
                "camber (mean line from chord line) (mm)",
            ),
        ] {
            draw_panel(area, sections, quantity, label).map_err(&failed)?;
        }
        root.present().map_err(&failed)?;
    }
    Ok(Some(svg))
}

type Area<'b> = DrawingArea<SVGBackend<'b>, plotters::coord::Shift>;

fn draw_panel(
    area: &Area,
    sections: &[InstanceSection],
    quantity: Quantity,
    label: &str,
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let lines: Vec<(&InstanceSection, Vec<(f64, f64)>)> = sections
        .iter()
        .filter_map(|s| Some((s, differences(s.distribution?, quantity))))
        .collect();
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..100.0, range(lines.iter().flat_map(|(_, l)| l)))?;
    chart
        .configure_mesh()
        .x_labels(11)
        .x_desc("along the chord from the leading edge (%)")
        .y_desc(label)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()?;
    for (section, line) in &lines {
        let colour = section.colour;
        chart
            .draw_series(LineSeries::new(
                line.iter().copied(),
                colour.stroke_width(2),
            ))?
            .label(section.instance)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()?;
    Ok(())
}

/// (place along the chord in %, measured minus nominal) at each measured station within the nominal's stations.
fn differences(distribution: &SectionDistribution, quantity: Quantity) -> Vec<(f64, f64)> {
    let k = quantity as usize;
    distribution
        .measured
        .iter()
        .filter_map(|station| {
            let nominal = interpolate(&distribution.nominal, station[0], k)?;
            Some((100.0 * station[0], station[k] - nominal))
        })
        .collect()
}

/// Value `k` of the stations (in increasing place along the chord) at place `at`, linearly between the two
/// about it; `None` outside them.
fn interpolate(stations: &[[f64; 3]], at: f64, k: usize) -> Option<f64> {
    let after = stations.iter().position(|s| s[0] >= at)?;
    if after == 0 {
        return (stations[0][0] == at).then_some(stations[0][k]);
    }
    let (a, b) = (stations[after - 1], stations[after]);
    let t = (at - a[0]) / (b[0] - a[0]);
    Some(a[k] + t * (b[k] - a[k]))
}

fn range<'a>(values: impl Iterator<Item = &'a (f64, f64)>) -> std::ops::Range<f64> {
    let (low, high) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(_, v)| {
        (lo.min(v), hi.max(v))
    });
    if !low.is_finite() {
        return -SMALLEST_SPAN_MM..SMALLEST_SPAN_MM;
    }
    let span = (high - low).max(SMALLEST_SPAN_MM);
    let middle = (high + low) / 2.0;
    let half = span * (0.5 + PADDING);
    middle - half..middle + half
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thinner_section_reads_its_thinning_at_every_station_between_the_nominals() {
        // Nominal thickness 10 mm falling to 2 mm along the chord; measured 3 % thinner, camber +0.05 mm, at
        // stations between the nominal's.
        let nominal: Vec<[f64; 3]> = (0..=10)
            .map(|k| {
                let at = k as f64 / 10.0;
                [at, 10.0 - 8.0 * at, at * (1.0 - at)]
            })
            .collect();
        let measured: Vec<[f64; 3]> = (0..10)
            .map(|k| {
                let at = 0.05 + k as f64 / 10.0;
                [at, 0.97 * (10.0 - 8.0 * at), at * (1.0 - at) + 0.05]
            })
            .collect();
        let distribution = SectionDistribution { nominal, measured };
        let thickness = differences(&distribution, Quantity::Thickness);
        assert_eq!(thickness.len(), 10);
        for (at, difference) in &thickness {
            let expected = -0.03 * (10.0 - 8.0 * at / 100.0);
            assert!((difference - expected).abs() < 1e-12, "{at}: {difference}");
        }
        // The nominal's camber is a parabola: between stations 0.1 apart, linear interpolation lies 0.0025 below
        // it at the middle, so the difference reads 0.05 + 0.0025.
        for (_, difference) in differences(&distribution, Quantity::Camber) {
            assert!((difference - 0.0525).abs() < 1e-12, "{difference}");
        }
        // Beyond the nominal's last station: nothing drawn.
        assert_eq!(interpolate(&distribution.nominal, 1.01, 1), None);
        assert_eq!(interpolate(&distribution.nominal, 0.0, 1), Some(10.0));
    }
}
