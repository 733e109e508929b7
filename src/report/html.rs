//! report.html: the part's report for a quality engineer's browser. Self-contained (inline CSS and SVG, no
//! scripts, nothing fetched), so that it can be mailed or archived as one file and still open years later.

use std::fmt::Write;
use std::path::Path;

use super::plots::{
    after_best_fit, deviation_svg, distribution_svg, profile_figures, whisker_svg, PlotError,
    ProfileFigures,
};
use super::summary::{
    deviation, machine_text, parameter_failures, parameter_tolerances_text, COORDINATE_DECIMALS,
    DEVIATION_DECIMALS,
};
use super::{PartReport, ProfileReport};
use crate::analysis::section::{ParameterValue, SectionParametersReport};
use crate::analysis::stats::{DeviationStats, Tolerance, Verdict};
use crate::analysis::tolerances::ParameterVerdict;
use crate::fsutil::write_atomically;

pub const HTML_FILE: &str = "report.html";

pub(super) const STYLE: &str = "body{font-family:sans-serif;margin:1.5em;color:#222}\
table{border-collapse:collapse;margin:0.5em 0 1.5em}\
th,td{border:1px solid #bbb;padding:0.2em 0.6em;text-align:right}\
th{background:#eee}td.name{text-align:left}\
.verdict{font-size:2.5em;font-weight:bold;padding:0.1em 0.5em;display:inline-block}\
.pass{color:#0a6b2d}.fail{color:#b00020}div.verdict.pass{background:#dff3e4}\
div.verdict.fail{background:#fbe0e4}dl{display:grid;grid-template-columns:max-content auto;gap:0.2em 1em}\
dt{font-weight:bold}dd{margin:0}figure{margin:1em 0}";

/// Writes dir/report.html atomically. Errors name the file.
pub fn write_html(dir: &Path, report: &PartReport) -> std::io::Result<()> {
    let path = dir.join(HTML_FILE);
    let html = report_html(report)
        .map_err(|e| std::io::Error::other(format!("cannot write {}: {e}", path.display())))?;
    write_atomically(&path, html.as_bytes())
}

/// The whole page.
fn report_html(report: &PartReport) -> Result<String, PlotError> {
    let title = escape(&format!(
        "{} {}: inspection report",
        report.part, report.serial
    ));
    let mut page = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{title}</title>\n\
         <style>{STYLE}</style>\n</head>\n<body>\n<h1>{title}</h1>\n"
    );
    page.push_str(&header_html(report));
    page.push_str(&instance_table(report));
    page.push_str(&profile_table(report));
    page.push_str(&best_fit_table(report));
    page.push_str(&parameters_table(report));
    page.push_str(&spacings_table(report));
    page.push_str(&figures_html(report)?);
    page.push_str("</body>\n</html>\n");
    Ok(page)
}

/// The verdict, big, and what was measured when, with what, against what.
fn header_html(report: &PartReport) -> String {
    let class = verdict_class(&report.verdict);
    let mut html = format!(
        "<div class=\"verdict {class}\">{}</div>\n<dl>\n",
        escape(&verdict_text(&report.verdict))
    );
    let machines: Vec<String> = report.machines.iter().map(machine_text).collect();
    let reference = &report.reference;
    let rows = [
        ("part", report.part.clone()),
        ("serial", report.serial.clone()),
        ("job", report.job.clone()),
        ("started", report.started.clone()),
        ("finished", report.finished.clone()),
        ("machines", machines.join("; ")),
        ("reference", reference.describe()),
        ("distance", report.distance.clone()),
        ("compensation", report.compensation.clone()),
        ("tolerance", tolerance_text(&report.tolerance)),
        (
            "units",
            "all lengths in mm; deviations positive outside the material".to_string(),
        ),
    ];
    let parameters = parameter_tolerances_text(report).map(|text| ("parameter tolerances", text));
    for (label, value) in rows.into_iter().chain(parameters) {
        writeln!(html, "<dt>{label}</dt><dd>{}</dd>", escape(&value)).expect("writing to a String");
    }
    html.push_str("</dl>\n");
    html
}

/// The columns after the names, as [`stats_row`] fills them.
const STATS_COLUMNS: [&str; 9] = [
    "points",
    "mean",
    "RMS",
    "min",
    "max",
    "worst",
    "worst at (x, y, z)",
    "tolerance",
    "verdict",
];

/// One row per instance, over all its profiles.
fn instance_table(report: &PartReport) -> String {
    let rows = report.instances.iter().map(|instance| {
        let names = [instance.name.as_str()];
        stats_row(
            &names,
            &instance.stats,
            &report.tolerance,
            &instance.verdict,
        )
    });
    table("Instances", &["instance"], rows)
}

/// One row per instance and profile.
fn profile_table(report: &PartReport) -> String {
    let rows = report.instances.iter().flat_map(|instance| {
        instance.profiles.iter().map(|profile: &ProfileReport| {
            let names = [
                instance.name.as_str(),
                profile.name.as_str(),
                profile.machine.as_str(),
            ];
            stats_row(&names, &profile.stats, &report.tolerance, &profile.verdict)
        })
    });
    table("Profiles", &["instance", "profile", "machine"], rows)
}

/// One row per instance and profile with a best fit: where the section lies and its form once that is removed,
/// by least squares and by minimum zone.
fn best_fit_table(report: &PartReport) -> String {
    let mut html = String::from(
        "<h2>Sections after a best fit (the translations, and in mode full the twist about the chord's middle)</h2>\
         \n<table>\n<tr><th>instance</th><th>profile</th><th>mode</th>\
         <th>method</th><th>along the thickness</th><th>along the chord</th>\
         <th>shift (y, z)</th><th>twist</th><th>form min</th><th>form max</th><th>form RMS</th><th>zone</th>\
         <th>held at its limit</th></tr>\n",
    );
    for instance in &report.instances {
        for profile in &instance.profiles {
            for fit in &profile.best_fits {
                let f = &fit.form;
                let cells = [
                    escape(&instance.name),
                    escape(&profile.name),
                    escape(&fit.mode),
                    escape(&fit.method),
                    deviation_mm(fit.dn_mm),
                    deviation_mm(fit.dchord_mm),
                    format!(
                        "({:+.DEVIATION_DECIMALS$}, {:+.DEVIATION_DECIMALS$}) mm",
                        fit.shift_mm[0], fit.shift_mm[1]
                    ),
                    format!("{:+.4} deg", fit.rotation_deg),
                    deviation_mm(f.min_mm),
                    deviation_mm(f.max_mm),
                    format!("{:.DEVIATION_DECIMALS$} mm", f.rms_mm),
                    format!("{:.DEVIATION_DECIMALS$} mm", f.zone_mm),
                    escape(&fit.held_at().unwrap_or_default()),
                ];
                html.push_str(&cells_row(cells));
            }
        }
    }
    html.push_str("</table>\n");
    html
}

/// The blade table: one row per section with parameters, each cell the measured value and its deviation from the
/// nominal. Left out when no section has parameters (a part whose reference is a solid).
fn parameters_table(report: &PartReport) -> String {
    let rows: Vec<(&str, &str, &SectionParametersReport)> = report
        .instances
        .iter()
        .flat_map(|i| i.profiles.iter().map(move |p| (i, p)))
        .filter_map(|(i, p)| Some((i.name.as_str(), p.name.as_str(), p.parameters.as_ref()?)))
        .collect();
    let Some(edge_distance_mm) = rows.first().map(|(_, _, p)| p.edge_distance_mm) else {
        return String::new();
    };
    let mut html = format!(
        "<h2>Section parameters, measured (deviation from nominal)</h2>\n<p>Chord between the two points farthest \
         apart; maximum thickness the largest inscribed circle; edge thicknesses {edge_distance_mm} mm in from each \
         edge; edge radii from a circle fitted at each round tip (from the scan's few points round a nose, repeatable \
         to about 0.1 mm: see BENCHMARKS.md); camber and chord angle (to the plane of rotation, +y) \
         from the mean line; pitch 2 &pi; r tan(chord \
         angle).</p>\n<table>\n<tr><th>instance</th><th>profile</th><th>chord</th><th>max thickness</th>\
         <th>leading-edge thickness</th><th>trailing-edge thickness</th><th>leading-edge radius</th>\
         <th>trailing-edge radius</th><th>max camber</th><th>chord angle</th>\
         <th>pitch</th><th>parameters</th></tr>\n"
    );
    let value = parameter_cell;
    for (instance, profile, p) in rows {
        let cells = [
            escape(instance),
            escape(profile),
            value(&p.chord_mm, "mm"),
            value(&p.max_thickness_mm, "mm"),
            value(&p.le_thickness_mm, "mm"),
            value(&p.te_thickness_mm, "mm"),
            radius_cell(p.le_radius_mm.as_ref()),
            radius_cell(p.te_radius_mm.as_ref()),
            value(&p.max_camber_mm, "mm"),
            value(&p.chord_angle_deg, "deg"),
            p.pitch_mm
                .as_ref()
                .map_or_else(|| "-".to_string(), |v| value(v, "mm")),
            p.verdict
                .map_or_else(|| "-".to_string(), parameter_verdict_html),
        ];
        html.push_str(&cells_row(cells));
    }
    html.push_str("</table>\n");
    html.push_str(&failures_list(report));
    html
}

/// An edge radius' cell; "sharp" where the edge (nominal or scanned) has no round.
fn radius_cell(radius: Option<&ParameterValue>) -> String {
    radius.map_or_else(|| "sharp".to_string(), |r| parameter_cell(r, "mm"))
}

/// A parameter's cell: measured (deviation from nominal); where it has a tolerance, marked pass or fail with the
/// limits and whose they are below.
fn parameter_cell(v: &ParameterValue, unit: &str) -> String {
    let text = format!("{:.4} {unit} ({:+.4})", v.measured, v.deviation);
    match (v.tolerance, v.verdict) {
        (Some(tolerance), Some(verdict)) => format!(
            "<span class=\"{}\">{text}</span><br><small>[{:+.4}, {:+.4}] {unit}, {}</small>",
            parameter_verdict_class(verdict),
            tolerance.lower,
            tolerance.upper,
            escape(&tolerance.from.to_string())
        ),
        _ => text,
    }
}

fn parameter_verdict_class(verdict: ParameterVerdict) -> &'static str {
    match verdict {
        ParameterVerdict::Pass => "pass",
        ParameterVerdict::Fail => "fail",
    }
}

fn parameter_verdict_html(verdict: ParameterVerdict) -> String {
    let class = parameter_verdict_class(verdict);
    format!("<span class=\"{class}\">{}</span>", class.to_uppercase())
}

/// Every parameter out of tolerance, as the summary lists them; nothing when none is.
fn failures_list(report: &PartReport) -> String {
    let failures = parameter_failures(report);
    if failures.is_empty() {
        return String::new();
    }
    let items: String = failures
        .iter()
        .map(|f| format!("<li class=\"fail\">{}</li>\n", escape(f)))
        .collect();
    format!("<h2>Parameters out of tolerance</h2>\n<ul>\n{items}</ul>\n")
}

/// Each blade's turn about the hub axis off its place, its angular spacing from the blade before it and its mean
/// pitch, then the propeller's mean pitch; nothing for parts that have none.
fn spacings_table(report: &PartReport) -> String {
    let rows: Vec<String> = report
        .instances
        .iter()
        .filter(|i| i.angular_spacing_deg.is_some() || i.blade_pitch_mm.is_some())
        .map(|i| {
            let turned = i
                .index_deg
                .map_or_else(|| "-".into(), |t| format!("{t:+.4} deg"));
            let spacing = i.angular_spacing_deg.as_ref();
            cells_row([
                escape(&i.name),
                turned,
                spacing.map_or_else(|| "-".into(), |s| parameter_cell(s, "deg")),
                spacing.map_or_else(|| "-".into(), |s| format!("{:.4} deg", s.nominal)),
                i.blade_pitch_mm
                    .as_ref()
                    .map_or_else(|| "-".into(), |p| parameter_cell(p, "mm")),
            ])
        })
        .collect();
    if rows.is_empty() {
        return String::new();
    }
    let propeller = report
        .propeller_pitch_mm
        .as_ref()
        .map_or_else(String::new, |p| {
            format!(
                "<p>Propeller mean pitch (the mean of its blades', nominal {:.4} mm): {}</p>\n",
                p.nominal,
                parameter_cell(p, "mm")
            )
        });
    format!(
        "<h2>Blade places and pitch</h2>\n<p>Each blade's turn about the hub axis off its place, from how far its \
         sections' chord middles lie along the tangent (r tan(turn) at radius r), its angular spacing from the blade \
         before it (the first from the last), and its mean pitch, the mean of its sections'.</p>\n<table>\n<tr>\
         <th>blade</th><th>turned</th><th>angular spacing (deviation)</th><th>nominal</th><th>mean pitch \
         (deviation)</th></tr>\n{}</table>\n{propeller}",
        rows.concat()
    )
}

/// A table row of plain cells, already escaped or formatted.
fn cells_row(cells: impl IntoIterator<Item = String>) -> String {
    let mut html = String::from("<tr>");
    for cell in cells {
        write!(html, "<td>{cell}</td>").expect("writing to a String");
    }
    html.push_str("</tr>\n");
    html
}

fn table(heading: &str, names: &[&str], rows: impl Iterator<Item = String>) -> String {
    let mut html = format!("<h2>{heading}</h2>\n<table>\n<tr>");
    for column in names.iter().chain(&STATS_COLUMNS) {
        write!(html, "<th>{column}</th>").expect("writing to a String");
    }
    html.push_str("</tr>\n");
    rows.for_each(|row| html.push_str(&row));
    html.push_str("</table>\n");
    html
}

fn stats_row(
    names: &[&str],
    stats: &DeviationStats,
    tolerance: &Tolerance,
    verdict: &Verdict,
) -> String {
    let mut html = String::from("<tr>");
    for name in names {
        write!(html, "<td class=\"name\">{}</td>", escape(name)).expect("writing to a String");
    }
    let at = stats
        .worst_at_mm
        .map(|c| format!("{c:.COORDINATE_DECIMALS$}"));
    let cells = [
        stats.points.to_string(),
        deviation_mm(stats.mean_mm),
        format!("{:.DEVIATION_DECIMALS$} mm", stats.rms_mm),
        deviation_mm(stats.min_mm),
        deviation_mm(stats.max_mm),
        deviation_mm(stats.worst_mm),
        format!("({}) mm", at.join(", ")),
        tolerance_text(tolerance),
    ];
    for cell in cells {
        write!(html, "<td>{cell}</td>").expect("writing to a String");
    }
    writeln!(
        html,
        "<td class=\"name {}\">{}</td></tr>",
        verdict_class(verdict),
        verdict.cell_text()
    )
    .expect("writing to a String");
    html
}

/// Per profile, the deviation figure then the whisker figure, with the instances that could not be drawn.
fn figures_html(report: &PartReport) -> Result<String, PlotError> {
    let mut html = String::from("<h2>Profiles: deviations</h2>\n");
    for figures in profile_figures(report) {
        html.push_str(&profile_figures_html(&figures, &report.tolerance)?);
    }
    Ok(html)
}

fn profile_figures_html(
    figures: &ProfileFigures,
    tolerance: &Tolerance,
) -> Result<String, PlotError> {
    let mut html = format!("<h3>Profile {}</h3>\n", escape(figures.name));
    if !figures.unplotted.is_empty() {
        writeln!(
            html,
            "<p>Not drawn (fewer than 3 points, or all on one line): {}</p>",
            escape(&figures.unplotted.join(", "))
        )
        .expect("writing to a String");
    }
    for svg in [
        deviation_svg(figures.name, &figures.sections, tolerance)?,
        whisker_svg(figures.name, &figures.sections)?,
    ] {
        writeln!(html, "<figure>\n{svg}\n</figure>").expect("writing to a String");
    }
    if let Some(fitted) = after_best_fit(&figures.sections) {
        let name = format!(
            "{} after the best fit (shift and twist removed)",
            figures.name
        );
        writeln!(
            html,
            "<figure>\n{}\n<figcaption>{}: each point's deviation once its section's least-squares best fit \
             (the shifts and twist in the best-fit table) is removed, its form error.</figcaption>\n</figure>",
            whisker_svg(&name, &fitted)?,
            escape(figures.name)
        )
        .expect("writing to a String");
    }
    if let Some(svg) = distribution_svg(figures.name, &figures.sections)? {
        writeln!(
            html,
            "<figure>\n{svg}\n<figcaption>{}: each blade's thickness (the diameter of the circle inscribed at each \
             station of its mean line) and camber (the mean line's distance from its chord line), measured minus \
             the nominal's at the same place along the chord.</figcaption>\n</figure>",
            escape(figures.name)
        )
        .expect("writing to a String");
    }
    Ok(html)
}

/// A signed deviation as the tables show it, e.g. "+0.0123 mm".
fn deviation_mm(mm: f64) -> String {
    format!("{} mm", deviation(mm))
}

fn tolerance_text(tolerance: &Tolerance) -> String {
    format!(
        "{} .. {}",
        deviation_mm(tolerance.lower_mm),
        deviation_mm(tolerance.upper_mm)
    )
}

fn verdict_text(verdict: &Verdict) -> String {
    verdict
        .what_failed()
        .map_or_else(|| "PASS".to_string(), |failed| format!("FAIL: {failed}"))
}

fn verdict_class(verdict: &Verdict) -> &'static str {
    match verdict {
        Verdict::Pass => "pass",
        Verdict::Fail { .. } => "fail",
    }
}

/// Text made safe inside HTML elements and attribute values (names and paths come from configuration).
pub(super) fn escape(text: &str) -> String {
    let mut escaped = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => escaped.push_str("&amp;"),
            '<' => escaped.push_str("&lt;"),
            '>' => escaped.push_str("&gt;"),
            '"' => escaped.push_str("&quot;"),
            '\'' => escaped.push_str("&#39;"),
            _ => escaped.push(c),
        }
    }
    escaped
}

#[cfg(test)]
pub(crate) mod tests;
