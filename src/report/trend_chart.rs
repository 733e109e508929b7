//! trend.html: the run chart of every profile of every instance over the parts of the history (each part's mean
//! deviation in the order inspected, against the tolerance band), with the trend table. Self-contained: inline SVG
//! drawn with plotters, no scripts.

use std::path::Path;

use plotters::prelude::*;

use super::html::escape;
use super::trend::{trend_text, TrendRow};
use crate::fsutil::write_atomically;

pub const TREND_FILE: &str = "trend.html";

const WIDTH: u32 = 900;
const HEIGHT: u32 = 320;
const BAND: RGBColor = RGBColor(120, 200, 120);

/// Writes `dir`/trend.html for the rows of `part_type`'s trend, atomically; returns the file's path.
pub fn write_trend_html(
    dir: &Path,
    part_type: &str,
    rows: &[TrendRow],
    lower_mm: f64,
    upper_mm: f64,
) -> std::io::Result<std::path::PathBuf> {
    let mut html = format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{part_type}: trend</title>\
         <style>body{{font-family:sans-serif;margin:2em}}pre{{background:#f4f4f4;padding:1em}}</style></head>\
         <body>\n<h1>{part_type}: trend over the inspected parts</h1>\n<pre>{}</pre>\n",
        escape(&trend_text(rows, lower_mm, upper_mm))
    );
    for row in rows {
        let svg = run_chart(row, lower_mm, upper_mm).map_err(std::io::Error::other)?;
        html.push_str(&format!(
            "<h2>instance {}, profile {}</h2>\n{svg}\n",
            escape(&row.instance),
            escape(&row.profile)
        ));
    }
    html.push_str("</body></html>\n");
    let path = dir.join(TREND_FILE);
    write_atomically(&path, html.as_bytes())?;
    Ok(path)
}

/// One profile's run chart: the parts' mean deviations in order, the tolerance band shaded, mm stated.
fn run_chart(row: &TrendRow, lower_mm: f64, upper_mm: f64) -> Result<String, String> {
    let failed = |e: DrawingAreaErrorKind<std::io::Error>| {
        format!(
            "cannot draw the run chart of {} {}: {e}",
            row.instance, row.profile
        )
    };
    let (lo, hi) = row
        .run_mm
        .iter()
        .fold((lower_mm, upper_mm), |(lo, hi), m| (lo.min(*m), hi.max(*m)));
    let pad = (hi - lo).max(1e-3) * 0.1;
    let parts = row.run_mm.len();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(failed)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "{} {}: mean deviation per part (mm), tolerance {lower_mm:+.3} .. {upper_mm:+.3} mm",
                    row.instance, row.profile
                ),
                ("sans-serif", 16),
            )
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(70)
            .build_cartesian_2d(0.5..parts as f64 + 0.5, lo - pad..hi + pad)
            .map_err(failed)?;
        chart
            .configure_mesh()
            .x_desc("part, in the order inspected")
            .y_desc("mean deviation (mm)")
            .draw()
            .map_err(failed)?;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(0.5, lower_mm), (parts as f64 + 0.5, upper_mm)],
                BAND.mix(0.25).filled(),
            )))
            .map_err(failed)?;
        let points: Vec<(f64, f64)> = row
            .run_mm
            .iter()
            .enumerate()
            .map(|(k, m)| ((k + 1) as f64, *m))
            .collect();
        chart
            .draw_series(LineSeries::new(points.clone(), &BLUE))
            .map_err(failed)?;
        chart
            .draw_series(points.into_iter().map(|p| Circle::new(p, 3, BLUE.filled())))
            .map_err(failed)?;
        root.present().map_err(failed)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_run_chart_per_profile_with_units_and_the_table() {
        let row = |profile: &str| TrendRow {
            instance: "B".into(),
            profile: profile.into(),
            parts: 3,
            mean_mm: 0.02,
            spread_mm: 0.01,
            cp: Some(3.33),
            cpk: Some(2.67),
            run_mm: vec![0.01, 0.02, 0.03],
        };
        let dir = tempfile::tempdir().unwrap();
        let path = write_trend_html(
            dir.path(),
            "propeller",
            &[row("r100"), row("r200")],
            -0.1,
            0.1,
        )
        .unwrap();
        let html = std::fs::read_to_string(path).unwrap();
        assert_eq!(html.matches("<svg").count(), 2);
        assert_eq!(html.matches("</svg>").count(), 2);
        assert!(
            html.contains("mean deviation per part (mm)"),
            "units on the plot"
        );
        assert!(
            html.contains("Cpk") && html.contains("2.67"),
            "the trend table"
        );
    }
}
