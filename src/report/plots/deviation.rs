//! Seed 003's figures 4-6: every instance's signed deviation along one profile, one line per instance, over the
//! tolerance band. The abscissa is the angle about the section's centroid from its chord, which names the same
//! place on every instance (unlike arc length, which shifts with where each scan started).

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::{InstanceSection, PlotError, SectionPoint};
use crate::analysis::stats::Tolerance;

const WIDTH: u32 = 1080;
/// The legend's column at the right, pixels; its rows start below the caption.
const LEGEND_WIDTH: u32 = 260;
const LEGEND_TOP: i32 = 50;
const LEGEND_ROW: i32 = 24;
const SAMPLE_LENGTH: i32 = 24;
const HEIGHT: u32 = 380;
const FIGURE: &str = "deviation";
/// Room above and below the data, as a share of its span.
const PADDING: f64 = 0.08;
/// The deviation span shown when every deviation and both bounds coincide, mm.
const SMALLEST_SPAN_MM: f64 = 0.001;
/// Consecutive points whose angles differ by more than this crossed the +-180 degree cut; no line joins them.
const WRAP_DEG: f64 = 180.0;
const BAND: RGBColor = RGBColor(120, 200, 120);

/// The deviation figure of profile `name` as an SVG document.
pub fn deviation_svg(
    name: &str,
    sections: &[InstanceSection],
    tolerance: &Tolerance,
) -> Result<String, PlotError> {
    let failed = PlotError::drawing(name, FIGURE);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(&failed)?;
        // The legend has its own column, beside the plot: inside it would hide some of the lines.
        let (plot, legend) = root.split_horizontally(WIDTH - LEGEND_WIDTH);
        let mut chart = ChartBuilder::on(&plot)
            .caption(
                format!("{name}: signed deviation along the section (mm, + outside the material)"),
                ("sans-serif", 18),
            )
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(-180.0..180.0, deviation_range(sections, tolerance))
            .map_err(&failed)?;
        chart
            .configure_mesh()
            .x_labels(13)
            .x_desc("angle about the section centroid from its chord (deg)")
            .y_desc("deviation (mm)")
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(&failed)?;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(-180.0, tolerance.lower_mm), (180.0, tolerance.upper_mm)],
                BAND.mix(0.25).filled(),
            )))
            .map_err(&failed)?;
        for section in sections {
            draw_instance(&mut chart, section).map_err(&failed)?;
        }
        draw_legend(&legend, sections, tolerance).map_err(&failed)?;
        root.present().map_err(&failed)?;
    }
    Ok(svg)
}

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
type Error = DrawingAreaErrorKind<std::io::Error>;

/// One instance's line, broken where it crosses the angle cut.
fn draw_instance(chart: &mut Chart, section: &InstanceSection) -> Result<(), Error> {
    let style = section.colour.stroke_width(2);
    for run in unwrapped_runs(&section.points) {
        let line = run.iter().map(|p| (p.angle_deg, p.deviation_mm));
        chart.draw_series(LineSeries::new(line, style))?;
    }
    Ok(())
}

/// The tolerance band's swatch, then one line sample per instance, each with its label.
fn draw_legend(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    sections: &[InstanceSection],
    tolerance: &Tolerance,
) -> Result<(), Error> {
    let font = ("sans-serif", 15).into_font();
    let row_y = |row: usize| LEGEND_TOP + LEGEND_ROW * row as i32;
    area.draw(&Rectangle::new(
        [(0, row_y(0) - 6), (SAMPLE_LENGTH, row_y(0) + 6)],
        BAND.mix(0.25).filled(),
    ))?;
    let band = format!(
        "tolerance {:+.3} .. {:+.3} mm",
        tolerance.lower_mm, tolerance.upper_mm
    );
    area.draw(&Text::new(
        band,
        (SAMPLE_LENGTH + 6, row_y(0) - 8),
        font.clone(),
    ))?;
    for (row, section) in sections.iter().enumerate() {
        let y = row_y(row + 1);
        area.draw(&PathElement::new(
            [(0, y), (SAMPLE_LENGTH, y)],
            section.colour.stroke_width(2),
        ))?;
        area.draw(&Text::new(
            section.instance,
            (SAMPLE_LENGTH + 6, y - 8),
            font.clone(),
        ))?;
    }
    Ok(())
}

/// The scan split where consecutive points jump across the +-180 degree cut.
fn unwrapped_runs(points: &[SectionPoint]) -> Vec<&[SectionPoint]> {
    let mut runs = Vec::new();
    let mut start = 0;
    for k in 1..points.len() {
        if (points[k].angle_deg - points[k - 1].angle_deg).abs() > WRAP_DEG {
            runs.push(&points[start..k]);
            start = k;
        }
    }
    runs.push(&points[start..]);
    runs
}

/// The deviations and the tolerance band with some room around them, mm.
fn deviation_range(sections: &[InstanceSection], tolerance: &Tolerance) -> std::ops::Range<f64> {
    let deviations = sections
        .iter()
        .flat_map(|s| &s.points)
        .map(|p| p.deviation_mm);
    let (low, high) = deviations
        .chain([tolerance.lower_mm, tolerance.upper_mm])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(low, high), d| {
            (low.min(d), high.max(d))
        });
    let pad = PADDING * (high - low).max(SMALLEST_SPAN_MM);
    low - pad..high + pad
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::*;

    fn at_angles(angles: &[f64]) -> Vec<SectionPoint> {
        angles
            .iter()
            .map(|&angle_deg| SectionPoint {
                u: 0.0,
                v: 0.0,
                normal: Vector2::zeros(),
                deviation_mm: angle_deg / 1000.0,
                after_fit_mm: None,
                angle_deg,
            })
            .collect()
    }

    #[test]
    fn the_line_breaks_only_where_the_scan_crosses_the_cut() {
        let points = at_angles(&[150.0, 170.0, -175.0, -160.0, -170.0, 175.0]);
        let runs: Vec<usize> = unwrapped_runs(&points).iter().map(|r| r.len()).collect();
        assert_eq!(runs, [2, 3, 1]);
    }

    #[test]
    fn the_range_holds_the_band_and_every_deviation() {
        let tolerance = Tolerance {
            lower_mm: -0.1,
            upper_mm: 0.1,
        };
        let sections = [InstanceSection {
            instance: "B",
            colour: BLACK,
            distribution: None,
            points: at_angles(&[-50.0, 120.0, 170.0]),
        }];
        let range = deviation_range(&sections, &tolerance);
        // From -0.1 (the band) to 0.17, padded by 8 % of the 0.27 mm span.
        assert!((range.start - (-0.1 - 0.0216)).abs() < 1e-12, "{range:?}");
        assert!((range.end - (0.17 + 0.0216)).abs() < 1e-12, "{range:?}");
    }
}
