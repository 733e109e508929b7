//! trend.html: the trend of a part type over its inspected parts, for a quality engineer's browser. What is
//! computed, stated on the page; a table of every profile's extremes, form and capability; a table of every blade
//! parameter's spread and capability; per profile its trend chart and a table of its parts by serial and date. Self-contained (inline CSS and SVG, no scripts).

use std::fmt::Write;
use std::path::{Path, PathBuf};

use super::html::{escape, STYLE};
use super::individuals::RUN_LENGTH;
use super::parameter_trend::ParameterTrendRow;
use super::summary::deviation;
use super::trend::{TrendRow, FEW_PARTS};
use super::trend_chart::trend_svg;
use crate::fsutil::write_atomically;

pub const TREND_FILE: &str = "trend.html";

/// The indices below this are shown as failing: the process makes parts outside the band.
const CAPABLE: f64 = 1.0;

const TREND_STYLE: &str = "td.fail{background:#fbe0e4}p.warning{color:#b00020;font-weight:bold}\
details{margin:0 0 2em}summary{cursor:pointer}";

/// Writes `dir`/trend.html for the rows of `part_type`'s trend, atomically; returns the file's path.
pub fn write_trend_html(
    dir: &Path,
    part_type: &str,
    rows: &[TrendRow],
    parameters: &[ParameterTrendRow],
    lower_mm: f64,
    upper_mm: f64,
) -> std::io::Result<PathBuf> {
    let path = dir.join(TREND_FILE);
    let html = trend_page(part_type, rows, parameters, lower_mm, upper_mm)
        .map_err(|e| std::io::Error::other(format!("cannot write {}: {e}", path.display())))?;
    write_atomically(&path, html.as_bytes())?;
    Ok(path)
}

fn trend_page(
    part_type: &str,
    rows: &[TrendRow],
    parameters: &[ParameterTrendRow],
    lower_mm: f64,
    upper_mm: f64,
) -> Result<String, String> {
    let title = escape(&format!("{part_type}: trend over the inspected parts"));
    let mut page = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{title}</title>\n\
         <style>{STYLE}{TREND_STYLE}</style>\n</head>\n<body>\n<h1>{title}</h1>\n"
    );
    page.push_str(&header(part_type, rows, lower_mm, upper_mm));
    page.push_str(&definitions(lower_mm, upper_mm));
    page.push_str(&profile_table(rows));
    if !parameters.is_empty() {
        page.push_str(&parameter_table(parameters));
    }
    for row in rows {
        write!(
            page,
            "<h2>Instance {}, profile {}</h2>\n<figure>\n{}\n</figure>\n",
            escape(&row.instance),
            escape(&row.profile),
            trend_svg(row, lower_mm, upper_mm)?
        )
        .expect("writing to a String");
        page.push_str(&parts_table(row, lower_mm, upper_mm));
    }
    page.push_str("</body>\n</html>\n");
    Ok(page)
}

/// What the trend covers, and a warning when the history is too short to trust the indices.
fn header(part_type: &str, rows: &[TrendRow], lower_mm: f64, upper_mm: f64) -> String {
    let dates = rows
        .iter()
        .flat_map(|r| r.parts.iter().map(|p| &p.finished));
    let (first, last) = (dates.clone().min(), dates.max());
    let mut html = String::from("<dl>\n");
    let entries = [
        ("part type", part_type.to_string()),
        (
            "inspections",
            format!(
                "{} to {}",
                first.map_or("-", |d| d.as_str()),
                last.map_or("-", |d| d.as_str())
            ),
        ),
        (
            "tolerance",
            format!("{} .. {} mm", deviation(lower_mm), deviation(upper_mm)),
        ),
        (
            "units",
            "all lengths in mm; deviations positive outside the material".to_string(),
        ),
    ];
    for (label, value) in entries {
        writeln!(html, "<dt>{label}</dt><dd>{}</dd>", escape(&value)).expect("writing to a String");
    }
    html.push_str("</dl>\n");
    let fewest = rows.iter().map(|r| r.parts.len()).min().unwrap_or(0);
    if fewest < FEW_PARTS {
        writeln!(
            html,
            "<p class=\"warning\">{fewest} parts in the history: Cp and Cpk need {FEW_PARTS} or more to be \
             trusted.</p>"
        )
        .expect("writing to a String");
    }
    html
}

/// Exactly what the numbers are, so that nobody reads them as capability of the mean.
fn definitions(lower_mm: f64, upper_mm: f64) -> String {
    let (lsl, usl) = (deviation(lower_mm), deviation(upper_mm));
    format!(
        "<h2>What is computed</h2>\n<ul>\n\
         <li>Per part and profile: <b>worst +</b> = the largest deviation of its points, <b>worst -</b> = the \
         smallest; the profile passes iff worst + &le; USL ({usl} mm) and worst - &ge; LSL ({lsl} mm). \
         <b>Form</b> = worst + minus worst -, the width of the zone about the nominal holding every point.</li>\n\
         <li>Over the parts: x&#772; the mean and s the sample standard deviation (n - 1) of each.</li>\n\
         <li><b>CPU</b> = (USL - x&#772; of worst +) / (3 s of worst +); <b>CPL</b> = (x&#772; of worst - - LSL) / \
         (3 s of worst -); <b>Cpk</b> = min(CPU, CPL).</li>\n\
         <li><b>Cp</b> = (USL - LSL - x&#772; of form) / (3 (s of worst + + s of worst -)): the Cpk the profile \
         would have with its position centred in the band; without form it is (USL - LSL) / 6&sigma;. It is \
         negative when the mean form alone is wider than the band.</li>\n\
         <li>Control charts: an individuals chart of each extreme, centre line the mean, control limits the mean \
         &plusmn; 2.66 &times; the mean moving range of consecutive parts. A part is ringed when it lies beyond a \
         control limit, or is the {RUN_LENGTH}th or later of a run on one side of the centre line.</li>\n\
         <li>The mean deviation is not used: a profile too fat on one side and too thin on the other averages to \
         zero.</li>\n</ul>\n"
    )
}

/// One row per instance and profile: extremes, form, capability, failures and control signals.
fn profile_table(rows: &[TrendRow]) -> String {
    let mut html = String::from(
        "<h2>Profiles</h2>\n<table>\n<tr><th rowspan=\"2\">instance</th><th rowspan=\"2\">profile</th>\
         <th rowspan=\"2\">parts</th><th rowspan=\"2\">failed</th><th colspan=\"3\">worst + (mm)</th>\
         <th colspan=\"3\">worst - (mm)</th><th colspan=\"2\">form (mm)</th><th rowspan=\"2\">Cp</th>\
         <th rowspan=\"2\">Cpk</th><th rowspan=\"2\">control signals</th></tr>\n\
         <tr><th>highest</th><th>mean</th><th>s</th><th>lowest</th><th>mean</th><th>s</th><th>mean</th>\
         <th>max</th></tr>\n",
    );
    for row in rows {
        let highest = row
            .parts
            .iter()
            .map(|p| p.worst_plus_mm)
            .fold(f64::NEG_INFINITY, f64::max);
        let lowest = row
            .parts
            .iter()
            .map(|p| p.worst_minus_mm)
            .fold(f64::INFINITY, f64::min);
        write!(
            html,
            "<tr><td class=\"name\">{}</td><td class=\"name\">{}</td><td>{}</td>{}",
            escape(&row.instance),
            escape(&row.profile),
            row.parts.len(),
            cell(row.failed().to_string(), row.failed() > 0)
        )
        .expect("writing to a String");
        for value in [
            deviation(highest),
            deviation(row.worst_plus.mean_mm),
            format!("{:.4}", row.worst_plus.spread_mm),
            deviation(lowest),
            deviation(row.worst_minus.mean_mm),
            format!("{:.4}", row.worst_minus.spread_mm),
            format!("{:.4}", row.form_mean_mm),
            format!("{:.4}", row.form_max_mm),
        ] {
            write!(html, "<td>{value}</td>").expect("writing to a String");
        }
        writeln!(
            html,
            "{}</tr>",
            capability_cells(row.cp, row.cpk, row.signalled())
        )
        .expect("writing to a String");
    }
    html.push_str("</table>\n");
    html
}

/// One row per blade parameter: the spread of its deviation from nominal over the parts and its capability.
fn parameter_table(rows: &[ParameterTrendRow]) -> String {
    let mut html = String::from(
        "<h2>Blade parameters</h2>\n<p>Per part the parameter's deviation from nominal (measured minus nominal, in \
         the parameter's unit); over the parts x&#772; its mean and s its sample standard deviation (n - 1). On \
         the newest inspection's tolerance [LSL, USL] of the deviation: <b>Cp</b> = (USL - LSL) / 6 s, <b>Cpk</b> \
         = min(USL - x&#772;, x&#772; - LSL) / 3 s. Control signals as for the profiles, on the deviation.</p>\n\
         <table>\n<tr><th>where</th><th>parameter</th><th>parts</th><th>failed</th><th>mean</th><th>s</th>\
         <th>tolerance</th><th>Cp</th><th>Cpk</th><th>control signals</th></tr>\n",
    );
    for row in rows {
        let unit = row.unit();
        let tolerance = row.limits.map_or("-".to_string(), |(lower, upper)| {
            format!("{lower:+.4} .. {upper:+.4} {unit}")
        });
        write!(
            html,
            "<tr><td class=\"name\">{}</td><td class=\"name\">{}</td><td>{}</td>{}<td>{:+.4} {unit}</td>\
             <td>{:.4} {unit}</td><td>{}</td>",
            escape(&row.place()),
            escape(&row.parameter),
            row.parts.len(),
            cell(row.failed().to_string(), row.failed() > 0),
            row.mean,
            row.spread,
            escape(&tolerance)
        )
        .expect("writing to a String");
        writeln!(
            html,
            "{}</tr>",
            capability_cells(row.cp, row.cpk, row.signalled())
        )
        .expect("writing to a String");
    }
    html.push_str("</table>\n");
    html
}

/// A profile's parts by serial and date, out-of-tolerance values and rule breaks marked.
fn parts_table(row: &TrendRow, lower_mm: f64, upper_mm: f64) -> String {
    let mut html = format!(
        "<details>\n<summary>The {} parts of {} {}</summary>\n<table>\n<tr><th>#</th><th>serial</th>\
         <th>inspected</th><th>worst + (mm)</th><th>worst - (mm)</th><th>form (mm)</th><th>verdict</th>\
         <th>control signals</th></tr>\n",
        row.parts.len(),
        escape(&row.instance),
        escape(&row.profile)
    );
    let outside = |v: f64| v > upper_mm || v < lower_mm;
    for (k, part) in row.parts.iter().enumerate() {
        let signals: Vec<String> = [("worst +", &row.worst_plus), ("worst -", &row.worst_minus)]
            .iter()
            .flat_map(|(name, extreme)| {
                extreme.chart.iter().flat_map(move |c| {
                    c.signals
                        .iter()
                        .filter(move |(at, _)| *at == k)
                        .map(move |(_, rule)| format!("{name} {}", rule.describe()))
                })
            })
            .collect();
        writeln!(
            html,
            "<tr><td>{}</td><td class=\"name\">{}</td><td class=\"name\">{}</td>{}{}<td>{:.4}</td>{}{}</tr>",
            k + 1,
            escape(&part.serial),
            escape(&part.finished),
            cell(deviation(part.worst_plus_mm), outside(part.worst_plus_mm)),
            cell(deviation(part.worst_minus_mm), outside(part.worst_minus_mm)),
            part.form_mm(),
            cell(
                if part.passed { "PASS" } else { "FAIL" }.to_string(),
                !part.passed
            ),
            cell(escape(&signals.join("; ")), !signals.is_empty())
        )
        .expect("writing to a String");
    }
    html.push_str("</table>\n</details>\n");
    html
}

/// The Cp, Cpk and control-signal cells of a row, each marked failing when it is below capable or signalled.
fn capability_cells(cp: Option<f64>, cpk: Option<f64>, signalled: usize) -> String {
    let mut cells: String = [cp, cpk]
        .iter()
        .map(|index| match index {
            Some(v) => cell(format!("{v:.2}"), *v < CAPABLE),
            None => "<td>-</td>".to_string(),
        })
        .collect();
    cells.push_str(&cell(signalled.to_string(), signalled > 0));
    cells
}

/// A table cell, marked failing when `bad`.
fn cell(content: String, bad: bool) -> String {
    if bad {
        format!("<td class=\"fail\">{content}</td>")
    } else {
        format!("<td>{content}</td>")
    }
}

#[cfg(test)]
mod tests;
