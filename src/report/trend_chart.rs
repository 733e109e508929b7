//! One profile's trend chart as an SVG document, drawn with plotters: per part (serial and date on the abscissa,
//! in the order inspected) the worst + and worst - deviation joined by the min/max envelope, over the tolerance
//! band; each extreme's individuals-chart centre line and control limits; parts outside the band marked red, parts
//! that break a control rule ringed.

use plotters::coord::combinators::WithKeyPoints;
use plotters::coord::types::{RangedCoordf64, RangedCoordi32};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::trend::{Extreme, TrendRow};

const WIDTH: u32 = 1080;
const HEIGHT: u32 = 420;
/// The legend's column at the right, pixels: inside the plot it would hide parts.
const LEGEND_WIDTH: u32 = 250;
const LEGEND_TOP: i32 = 50;
const LEGEND_ROW: i32 = 24;
const SAMPLE_LENGTH: i32 = 24;
/// Room for the abscissa's labels, written upwards: serial and date.
const X_LABEL_AREA: u32 = 175;
/// Pixels between the axis and the parts' labels, past the tick marks.
const LABEL_GAP: i32 = 10;
/// At most this many parts are labelled; past it every k-th, so that the labels never overlap.
const MOST_LABELS: usize = 25;
/// Room above and below the data, as a share of its span.
const PADDING: f64 = 0.08;
/// The span shown when every value and both limits coincide, mm.
const SMALLEST_SPAN_MM: f64 = 0.001;

const BAND: RGBColor = RGBColor(120, 200, 120);
const ENVELOPE: RGBColor = RGBColor(150, 150, 150);
/// Okabe and Ito's vermilion and blue for the two extremes (colour-blind safe), red for out of tolerance.
const PLUS: RGBColor = RGBColor(213, 94, 0);
const MINUS: RGBColor = RGBColor(0, 114, 178);
const OUTSIDE: RGBColor = RGBColor(200, 0, 30);
/// The ring around a part that breaks a control rule, pixels.
const RING_RADIUS: u32 = 9;

type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<WithKeyPoints<RangedCoordi32>, RangedCoordf64>>;
type Error = DrawingAreaErrorKind<std::io::Error>;

/// The trend chart of `row` against the band `lower_mm` .. `upper_mm`.
pub fn trend_svg(row: &TrendRow, lower_mm: f64, upper_mm: f64) -> Result<String, String> {
    let failed = |e: Error| {
        format!(
            "cannot draw the trend chart of {} {}: {e}",
            row.instance, row.profile
        )
    };
    let parts = row.parts.len();
    let every = parts.div_ceil(MOST_LABELS).max(1);
    let ticks: Vec<i32> = (1..=parts).step_by(every).map(|k| k as i32).collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(failed)?;
        let (plot, legend) = root.split_horizontally(WIDTH - LEGEND_WIDTH);
        let mut chart = ChartBuilder::on(&plot)
            .caption(
                format!(
                    "{} {}: worst + and worst - deviation per part (mm)",
                    row.instance, row.profile
                ),
                ("sans-serif", 18),
            )
            .margin(10)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(75)
            .build_cartesian_2d(
                (0..parts as i32 + 1).with_key_points(ticks.clone()),
                value_range(row, lower_mm, upper_mm),
            )
            .map_err(failed)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            // Before the abscissa's own style, which it would otherwise replace.
            .label_style(("sans-serif", 14))
            // The parts' labels are drawn below, upright text would overlap.
            .x_label_formatter(&|_| String::new())
            .y_label_formatter(&|y| millimetres(*y))
            .x_desc("part: serial and inspection date, in the order inspected")
            .y_desc("deviation (mm)")
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(failed)?;
        let span = (0, parts as i32 + 1);
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(span.0, lower_mm), (span.1, upper_mm)],
                BAND.mix(0.2).filled(),
            )))
            .map_err(failed)?;
        for limit in [lower_mm, upper_mm] {
            chart
                .draw_series(LineSeries::new(
                    [(span.0, limit), (span.1, limit)],
                    BAND.stroke_width(2),
                ))
                .map_err(failed)?;
        }
        draw_envelope(&mut chart, row).map_err(failed)?;
        for (extreme, colour) in [(&row.worst_plus, PLUS), (&row.worst_minus, MINUS)] {
            draw_limits(&mut chart, extreme, colour, span).map_err(failed)?;
        }
        let plus = row.parts.iter().map(|p| p.worst_plus_mm);
        let minus = row.parts.iter().map(|p| p.worst_minus_mm);
        let outside = |v: f64| v > upper_mm || v < lower_mm;
        draw_extreme(&mut chart, plus.collect(), &row.worst_plus, PLUS, outside).map_err(failed)?;
        draw_extreme(
            &mut chart,
            minus.collect(),
            &row.worst_minus,
            MINUS,
            outside,
        )
        .map_err(failed)?;
        draw_part_labels(&plot, &chart, row, &ticks).map_err(failed)?;
        draw_legend(&legend, lower_mm, upper_mm).map_err(failed)?;
        root.present().map_err(failed)?;
    }
    Ok(svg)
}

/// Each ticked part's serial and date, written upwards below the axis so that long serials never overlap
/// (plotters centres its own rotated labels on the axis, across the plot).
fn draw_part_labels(
    plot: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    chart: &Chart,
    row: &TrendRow,
    ticks: &[i32],
) -> Result<(), Error> {
    let bottom = chart.y_range().start;
    let style = ("sans-serif", 13)
        .into_text_style(plot)
        .transform(FontTransform::Rotate270)
        .pos(Pos::new(HPos::Right, VPos::Center));
    for &k in ticks {
        let part = &row.parts[k as usize - 1];
        let (x, y) = chart.backend_coord(&(k, bottom));
        plot.draw(&Text::new(
            format!("{}  {}", part.serial, short_date(&part.finished)),
            (x, y + LABEL_GAP),
            style.clone(),
        ))?;
    }
    Ok(())
}

/// A tick's deviation to the micrometre, signed, with no "-0.000" for a zero that rounding left negative.
fn millimetres(mm: f64) -> String {
    let rounded = (mm * 1000.0).round() / 1000.0 + 0.0;
    format!("{rounded:+.3}")
}

/// "2026-11-23 10:00" of an RFC 3339 time (the seconds and zone dropped to keep the label short).
fn short_date(rfc3339: &str) -> String {
    rfc3339.get(..16).unwrap_or(rfc3339).replacen('T', " ", 1)
}

/// The ordinates to show: every value, both tolerance limits and every control limit, padded.
fn value_range(row: &TrendRow, lower_mm: f64, upper_mm: f64) -> std::ops::Range<f64> {
    let limits = [&row.worst_plus, &row.worst_minus]
        .into_iter()
        .filter_map(|e| e.chart.as_ref())
        .flat_map(|c| [c.lower_limit, c.upper_limit]);
    let values = row
        .parts
        .iter()
        .flat_map(|p| [p.worst_plus_mm, p.worst_minus_mm]);
    let (lo, hi) = values
        .chain(limits)
        .fold((lower_mm, upper_mm), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let pad = (hi - lo).max(SMALLEST_SPAN_MM) * PADDING;
    lo - pad..hi + pad
}

/// Each part's span from worst - to worst +, shaded between consecutive parts and a bar at each.
fn draw_envelope(chart: &mut Chart, row: &TrendRow) -> Result<(), Error> {
    let at = |k: usize| (k + 1) as i32;
    let outline: Vec<(i32, f64)> = (row.parts.iter().enumerate())
        .map(|(k, p)| (at(k), p.worst_plus_mm))
        .chain((row.parts.iter().enumerate().rev()).map(|(k, p)| (at(k), p.worst_minus_mm)))
        .collect();
    chart.draw_series(std::iter::once(Polygon::new(
        outline,
        ENVELOPE.mix(0.25).filled(),
    )))?;
    chart.draw_series(row.parts.iter().enumerate().map(|(k, p)| {
        PathElement::new(
            [(at(k), p.worst_minus_mm), (at(k), p.worst_plus_mm)],
            ENVELOPE.stroke_width(2),
        )
    }))?;
    Ok(())
}

/// An extreme's centre line (solid) and control limits (dashed).
fn draw_limits(
    chart: &mut Chart,
    extreme: &Extreme,
    colour: RGBColor,
    (from, to): (i32, i32),
) -> Result<(), Error> {
    let Some(control) = &extreme.chart else {
        return Ok(());
    };
    chart.draw_series(LineSeries::new(
        [(from, control.centre), (to, control.centre)],
        colour.mix(0.6).stroke_width(1),
    ))?;
    for limit in [control.lower_limit, control.upper_limit] {
        chart.draw_series(DashedLineSeries::new(
            [(from, limit), (to, limit)],
            8,
            5,
            colour.stroke_width(1),
        ))?;
    }
    Ok(())
}

/// An extreme's run: a line through its parts, a dot each, red where `outside` the band (a worst - above the
/// upper limit is outside too), a ring where a control rule is broken.
fn draw_extreme(
    chart: &mut Chart,
    values: Vec<f64>,
    extreme: &Extreme,
    colour: RGBColor,
    outside: impl Fn(f64) -> bool,
) -> Result<(), Error> {
    let points: Vec<(i32, f64)> = (values.iter().enumerate())
        .map(|(k, v)| ((k + 1) as i32, *v))
        .collect();
    chart.draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?;
    chart.draw_series(points.iter().map(|&(x, v)| {
        if outside(v) {
            Circle::new((x, v), 5, OUTSIDE.filled())
        } else {
            Circle::new((x, v), 4, colour.filled())
        }
    }))?;
    // One ring per part, even where it breaks both rules.
    let mut signalled: Vec<usize> = (extreme.chart.iter())
        .flat_map(|c| c.signals.iter().map(|(k, _)| *k))
        .collect();
    signalled.dedup();
    chart.draw_series(
        signalled
            .into_iter()
            .map(|k| Circle::new(points[k], RING_RADIUS, BLACK.stroke_width(2))),
    )?;
    Ok(())
}

/// How the legend shows a kind of mark.
enum Sample {
    Line(ShapeStyle),
    Dashed(ShapeStyle),
    /// A dot or ring of the radius given, pixels.
    Mark(ShapeStyle, u32),
}

/// The key, one row per kind of mark.
fn draw_legend(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    lower_mm: f64,
    upper_mm: f64,
) -> Result<(), Error> {
    let style = ("sans-serif", 14)
        .into_text_style(area)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let band = format!("tolerance {lower_mm:+.3} .. {upper_mm:+.3}");
    let rows = [
        (band.as_str(), Sample::Line(BAND.stroke_width(8))),
        ("worst + (max) per part", Sample::Line(PLUS.stroke_width(2))),
        (
            "worst - (min) per part",
            Sample::Line(MINUS.stroke_width(2)),
        ),
        ("min/max envelope", Sample::Line(ENVELOPE.stroke_width(8))),
        (
            "centre line (mean)",
            Sample::Line(PLUS.mix(0.6).stroke_width(1)),
        ),
        ("control limits", Sample::Dashed(PLUS.stroke_width(1))),
        ("outside the tolerance", Sample::Mark(OUTSIDE.filled(), 5)),
        (
            "breaks a control rule",
            Sample::Mark(BLACK.stroke_width(2), RING_RADIUS),
        ),
    ];
    for (k, (text, sample)) in rows.into_iter().enumerate() {
        let y = LEGEND_TOP + k as i32 * LEGEND_ROW;
        match sample {
            Sample::Line(shape) => {
                area.draw(&PathElement::new([(10, y), (10 + SAMPLE_LENGTH, y)], shape))?
            }
            Sample::Dashed(shape) => {
                for dash in [0, 10, 20] {
                    area.draw(&PathElement::new([(10 + dash, y), (14 + dash, y)], shape))?;
                }
            }
            Sample::Mark(shape, radius) => {
                area.draw(&Circle::new((10 + SAMPLE_LENGTH / 2, y), radius, shape))?
            }
        }
        area.draw(&Text::new(
            text.to_string(),
            (18 + SAMPLE_LENGTH, y),
            style.clone(),
        ))?;
    }
    Ok(())
}
