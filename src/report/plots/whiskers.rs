//! The whisker figure of one profile: each instance's section in its own plane (one panel per instance), every
//! point's deviation drawn from the point along its normal, magnified so that it can be seen, red outside the
//! material and blue inside. One magnification serves all panels, so that the instances compare at a glance.

use plotters::prelude::*;

use super::{InstanceSection, PlotError, SectionPoint};

const PANEL_WIDTH: u32 = 460;
const HEIGHT: u32 = 480;
/// Wide enough for the figure's title with a single panel.
const SMALLEST_WIDTH: u32 = 900;
const FIGURE: &str = "whisker";
const MARGIN: u32 = 10;
const X_LABEL_AREA: u32 = 40;
const Y_LABEL_AREA: u32 = 60;
/// The largest whisker is about this share of the largest section's size.
const WHISKER_SHARE: f64 = 0.1;
/// Room around a section and its whiskers, as a share of their extent.
const PADDING: f64 = 0.05;
const OUTSIDE: RGBColor = RGBColor(200, 30, 30);
const INSIDE: RGBColor = RGBColor(30, 70, 200);
const OUTLINE: RGBColor = RGBColor(110, 110, 110);

/// The whisker figure of profile `name` as an SVG document.
pub fn whisker_svg(name: &str, sections: &[InstanceSection]) -> Result<String, PlotError> {
    let failed = PlotError::drawing(name, FIGURE);
    let magnification = magnification(sections);
    let width = (PANEL_WIDTH * sections.len().max(1) as u32).max(SMALLEST_WIDTH);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(&failed)?;
        let title = format!(
            "{name}: sections in their planes (mm); deviations along the normals, whiskers x {magnification} \
             (red outside, blue inside the material)"
        );
        let body = root.titled(&title, ("sans-serif", 17)).map_err(&failed)?;
        let panels = body.split_evenly((1, sections.len().max(1)));
        for (panel, section) in panels.iter().zip(sections) {
            draw_panel(panel, section, magnification).map_err(&failed)?;
        }
        root.present().map_err(&failed)?;
    }
    Ok(svg)
}

type Area<'b> = DrawingArea<SVGBackend<'b>, plotters::coord::Shift>;

/// One instance's section, outline and whiskers, at equal scales on both axes so that whiskers stand
/// perpendicular to the outline.
fn draw_panel(
    panel: &Area,
    section: &InstanceSection,
    magnification: f64,
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let area = panel.titled(section.instance, ("sans-serif", 16))?;
    let (width, height) = area.dim_in_pixel();
    let plot_pixels = (
        width.saturating_sub(2 * MARGIN + Y_LABEL_AREA).max(1),
        height.saturating_sub(2 * MARGIN + X_LABEL_AREA).max(1),
    );
    let whiskers: Vec<Whisker> = section
        .points
        .iter()
        .filter_map(|p| whisker(p, magnification))
        .collect();
    let (u_range, v_range) = equal_scale_ranges(&section.points, &whiskers, plot_pixels);
    let mut chart = ChartBuilder::on(&area)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(u_range, v_range)?;
    chart
        .configure_mesh()
        .x_labels(6)
        .y_labels(6)
        .x_desc("u, horizontal (mm)")
        .y_desc("v, up (mm)")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()?;
    let outline = section.points.iter().map(|p| (p.u, p.v));
    chart.draw_series(LineSeries::new(outline, OUTLINE.stroke_width(1)))?;
    chart.draw_series(whiskers.iter().map(|w| {
        let colour = if w.outside { OUTSIDE } else { INSIDE };
        PathElement::new([w.from, w.to], colour.stroke_width(1))
    }))?;
    Ok(())
}

/// A point's deviation drawn along its in-plane normal, in plane coordinates (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Whisker {
    from: (f64, f64),
    to: (f64, f64),
    outside: bool,
}

/// `None` for a point with no deviation or no in-plane normal (nothing to draw).
fn whisker(point: &SectionPoint, magnification: f64) -> Option<Whisker> {
    let length = point.deviation_mm * magnification;
    let offset = point.normal * length;
    (offset.norm() > 0.0).then(|| Whisker {
        from: (point.u, point.v),
        to: (point.u + offset.x, point.v + offset.y),
        outside: point.deviation_mm > 0.0,
    })
}

/// The "nice" factor (1, 2 or 5 times a power of ten, nearest on a log scale) that makes the largest whisker
/// about [`WHISKER_SHARE`] of the largest section's extent; 1 when there is nothing to magnify.
fn magnification(sections: &[InstanceSection]) -> f64 {
    let points = || sections.iter().flat_map(|s| &s.points);
    let largest = points().map(|p| p.deviation_mm.abs()).fold(0.0, f64::max);
    let size = sections
        .iter()
        .map(|s| extent(s.points.iter().map(|p| (p.u, p.v))))
        .map(|(u, v)| (u.end - u.start).max(v.end - v.start))
        .fold(0.0, f64::max);
    if largest > 0.0 && size > 0.0 {
        nice(WHISKER_SHARE * size / largest)
    } else {
        1.0
    }
}

/// The nearest of 1, 2, 5 times a power of ten, on a log scale, to a positive `raw`.
fn nice(raw: f64) -> f64 {
    let exponent = raw.log10().floor() as i32;
    let decade = |mantissa: f64, e: i32| {
        // Divide by an exact power of ten for negative exponents, so that 0.2 prints as 0.2.
        if e >= 0 {
            mantissa * 10f64.powi(e)
        } else {
            mantissa / 10f64.powi(-e)
        }
    };
    [1.0, 2.0, 5.0, 10.0]
        .map(|m| decade(m, exponent))
        .into_iter()
        .min_by(|a, b| (raw / a).ln().abs().total_cmp(&(raw / b).ln().abs()))
        .expect("four candidates")
}

type Span = std::ops::Range<f64>;

/// The smallest ranges holding every point and whisker tip, widened (about their centre) so that a millimetre
/// takes as many pixels along u as along v in a plotting area of `pixels`.
fn equal_scale_ranges(
    points: &[SectionPoint],
    whiskers: &[Whisker],
    pixels: (u32, u32),
) -> (Span, Span) {
    let (u, v) = extent(
        points
            .iter()
            .map(|p| (p.u, p.v))
            .chain(whiskers.iter().map(|w| w.to)),
    );
    let (pixels_u, pixels_v) = (pixels.0 as f64, pixels.1 as f64);
    let mm_per_pixel =
        ((u.end - u.start) / pixels_u).max((v.end - v.start) / pixels_v) * (1.0 + 2.0 * PADDING);
    // A single point has no extent: show a millimetre around it.
    let mm_per_pixel = if mm_per_pixel > 0.0 {
        mm_per_pixel
    } else {
        1.0 / pixels_u.min(pixels_v)
    };
    let around = |span: Span, pixels: f64| {
        let centre = (span.start + span.end) / 2.0;
        let half = mm_per_pixel * pixels / 2.0;
        centre - half..centre + half
    };
    (around(u, pixels_u), around(v, pixels_v))
}

/// The u and v ranges of some plane points.
fn extent(points: impl Iterator<Item = (f64, f64)>) -> (Span, Span) {
    points.fold(
        (
            f64::INFINITY..f64::NEG_INFINITY,
            f64::INFINITY..f64::NEG_INFINITY,
        ),
        |(u, v), (pu, pv)| {
            (
                u.start.min(pu)..u.end.max(pu),
                v.start.min(pv)..v.end.max(pv),
            )
        },
    )
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::*;

    fn point(u: f64, v: f64, normal: [f64; 2], deviation_mm: f64) -> SectionPoint {
        SectionPoint {
            u,
            v,
            normal: Vector2::from(normal),
            deviation_mm,
            after_fit_mm: None,
            angle_deg: 0.0,
        }
    }

    #[test]
    fn magnification_is_a_round_number_near_a_tenth_of_the_section() {
        assert_eq!(nice(16.1), 20.0);
        assert_eq!(nice(13.0), 10.0);
        assert_eq!(nice(3.3), 5.0);
        assert_eq!(nice(0.31), 0.2);
        assert_eq!(nice(800.0), 1000.0);
        // A 150 mm section with 0.93 mm at worst: 0.1 * 150 / 0.93 = 16.1, drawn x 20.
        let sections = [InstanceSection {
            instance: "B",
            colour: BLACK,
            distribution: None,
            points: vec![
                point(0.0, 0.0, [0.0, 1.0], -0.93),
                point(150.0, 10.0, [0.0, 1.0], 0.2),
            ],
        }];
        assert_eq!(magnification(&sections), 20.0);
    }

    #[test]
    fn whiskers_run_along_the_normal_signed_by_the_deviation() {
        let outward = whisker(&point(3.0, 4.0, [0.6, 0.8], 0.5), 10.0).unwrap();
        assert_eq!(outward.from, (3.0, 4.0));
        assert!((outward.to.0 - 6.0).abs() < 1e-12 && (outward.to.1 - 8.0).abs() < 1e-12);
        assert!(outward.outside);
        let inward = whisker(&point(3.0, 4.0, [0.6, 0.8], -0.5), 10.0).unwrap();
        assert!((inward.to.0 - 0.0).abs() < 1e-12 && (inward.to.1 - 0.0).abs() < 1e-12);
        assert!(!inward.outside);
        assert_eq!(whisker(&point(3.0, 4.0, [0.0, 0.0], 0.5), 10.0), None);
        assert_eq!(whisker(&point(3.0, 4.0, [0.6, 0.8], 0.0), 10.0), None);
    }

    #[test]
    fn both_axes_get_the_same_millimetres_per_pixel() {
        let points = [
            point(0.0, 0.0, [0.0, 1.0], 0.0),
            point(100.0, 10.0, [0.0, 1.0], 0.0),
        ];
        let (u, v) = equal_scale_ranges(&points, &[], (400, 200));
        let scale_u = (u.end - u.start) / 400.0;
        let scale_v = (v.end - v.start) / 200.0;
        assert!((scale_u - scale_v).abs() < 1e-12, "{u:?} {v:?}");
        // The wide section sets the scale: 100 mm padded by 5 % each side over 400 pixels.
        assert!((scale_u - 110.0 / 400.0).abs() < 1e-12);
        assert!(((v.start + v.end) / 2.0 - 5.0).abs() < 1e-12);
    }
}
