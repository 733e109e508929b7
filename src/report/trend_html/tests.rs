use quick_xml::events::Event;

use super::*;
use crate::report::html::tests::svgs;
use crate::report::parameter_trend::parameter_trend;
use crate::report::store::{ParameterRecord, ProfileRecord};
use crate::report::trend::trend;

const LOWER: f64 = -0.1;
const UPPER: f64 = 0.1;
const PARTS: usize = 12;

fn record(k: usize, instance: &str, min_mm: f64, max_mm: f64) -> ProfileRecord {
    ProfileRecord {
        serial: format!("SN-{}", k + 1),
        finished: format!("2026-11-{:02}T08:30:00Z", k + 1),
        instance: instance.into(),
        profile: "r100".into(),
        points: 300,
        mean_mm: (min_mm + max_mm) / 2.0,
        rms_mm: max_mm.abs().max(min_mm.abs()),
        min_mm,
        max_mm,
        passed: min_mm >= LOWER && max_mm <= UPPER,
        rescans: 0,
        lower_mm: LOWER,
        upper_mm: UPPER,
    }
}

/// Twelve parts: blade A inside the band but for part 12, whose worst + jumps to +0.15 mm (outside, and beyond
/// the control limit 0.0900 mm: centre 0.06, mean moving range 0.124 / 11); the eleven before lie below that
/// centre, so parts 8 to 11 break the run rule. Blade B shifted outwards, every point of every part above the
/// band.
fn history() -> Vec<ProfileRecord> {
    (0..PARTS)
        .flat_map(|k| {
            let wobble = 0.002 * (k % 3) as f64;
            let a_plus = if k == PARTS - 1 { 0.15 } else { 0.05 + wobble };
            [
                record(k, "A", -0.05 - wobble, a_plus),
                record(k, "B", 0.30 + wobble, 0.52 - wobble),
            ]
        })
        .collect()
}

fn page() -> (Vec<TrendRow>, String) {
    let rows = trend(&history(), LOWER, UPPER);
    let html = trend_page("propeller", &rows, &[], LOWER, UPPER).unwrap();
    (rows, html)
}

/// One table cell: its text and whether it is marked failing.
#[derive(Debug, Clone, PartialEq)]
struct Cell {
    text: String,
    failing: bool,
}

/// Every `<table>` of the page as its rows of data cells (header rows, all `<th>`, are left out).
fn tables(html: &str) -> Vec<Vec<Vec<Cell>>> {
    html.match_indices("<table>")
        .map(|(start, _)| {
            let end = html[start..].find("</table>").expect("a closed table") + start;
            rows_of(&html[start..end + "</table>".len()])
        })
        .collect()
}

fn rows_of(table: &str) -> Vec<Vec<Cell>> {
    let mut reader = quick_xml::Reader::from_str(table);
    let (mut rows, mut cell): (Vec<Vec<Cell>>, Option<Cell>) = (Vec::new(), None);
    loop {
        match reader.read_event().expect("a well-formed table") {
            Event::Start(e) if e.name().as_ref() == b"tr" => rows.push(Vec::new()),
            Event::Start(e) if e.name().as_ref() == b"td" => {
                let class = e
                    .try_get_attribute("class")
                    .unwrap()
                    .map(|a| String::from_utf8_lossy(&a.value).into_owned());
                cell = Some(Cell {
                    text: String::new(),
                    failing: class.is_some_and(|c| c.split(' ').any(|c| c == "fail")),
                });
            }
            Event::Text(t) => {
                if let Some(cell) = cell.as_mut() {
                    cell.text.push_str(&t.decode().unwrap());
                }
            }
            Event::GeneralRef(r) => {
                if let Some(cell) = cell.as_mut() {
                    cell.text
                        .push_str(&format!("&{};", String::from_utf8_lossy(&r)));
                }
            }
            Event::End(e) if e.name().as_ref() == b"td" => {
                let done = cell.take().expect("a cell was open");
                rows.last_mut().expect("a row").push(done);
            }
            Event::Eof => break,
            _ => {}
        }
    }
    rows.retain(|row| !row.is_empty());
    rows
}

fn texts(row: &[Cell]) -> Vec<&str> {
    row.iter().map(|c| c.text.as_str()).collect()
}

#[test]
fn the_profile_table_is_an_html_table_with_capability_of_the_extremes() {
    let (rows, html) = page();
    assert!(!html.contains("<pre"), "no preformatted dump");
    let tables = tables(&html);
    // The profile table, then one table of parts per profile.
    assert_eq!(tables.len(), 1 + rows.len());
    let profiles = &tables[0];
    assert_eq!(profiles.len(), 2);
    let b = &profiles[1];
    let b_row = &rows[1];
    assert_eq!(
        texts(b),
        [
            "B",
            "r100",
            "12",
            "12",
            "+0.5200",
            &format!("{:+.4}", b_row.worst_plus.mean_mm),
            &format!("{:.4}", b_row.worst_plus.spread_mm),
            "+0.3000",
            &format!("{:+.4}", b_row.worst_minus.mean_mm),
            &format!("{:.4}", b_row.worst_minus.spread_mm),
            &format!("{:.4}", b_row.form_mean_mm),
            "0.2200",
            &format!("{:.2}", b_row.cp.unwrap()),
            &format!("{:.2}", b_row.cpk.unwrap()),
            "0"
        ]
    );
    // Every part of B fails, and the profile cannot be capable: its worst - sits 0.40 mm above the band.
    assert!(
        b_row.cpk.unwrap() < 0.0 && b_row.cp.unwrap() < 1.0,
        "{b_row:?}"
    );
    assert!(b[3].failing && b[12].failing && b[13].failing, "{b:?}");
    assert!(!b[2].failing && !b[14].failing);
    let a = &profiles[0];
    assert_eq!((a[0].text.as_str(), a[3].text.as_str()), ("A", "1"));
    assert_eq!(
        (a[14].text.as_str(), a[14].failing),
        ("5", true),
        "parts 8 to 12 of A: {a:?}"
    );
}

#[test]
fn each_profile_lists_its_parts_by_serial_and_date_with_failures_marked() {
    let (_, html) = page();
    let tables = tables(&html);
    let a_parts = &tables[1];
    assert_eq!(a_parts.len(), PARTS);
    for (k, part) in a_parts.iter().enumerate() {
        assert_eq!(part[0].text, (k + 1).to_string());
        assert_eq!(part[1].text, format!("SN-{}", k + 1));
        assert_eq!(part[2].text, format!("2026-11-{:02}T08:30:00Z", k + 1));
    }
    let last = &a_parts[PARTS - 1];
    assert_eq!(last[3].text, "+0.1500");
    assert!(last[3].failing && !last[4].failing, "{last:?}");
    assert_eq!((last[6].text.as_str(), last[6].failing), ("FAIL", true));
    assert_eq!(last[7].text, "worst + beyond a control limit");
    assert!(!a_parts[0][3].failing && a_parts[6][7].text.is_empty());
    assert_eq!(
        a_parts[7][7].text,
        "worst + 8 or more in a row on one side of the centre"
    );
    // B's worst - is above the band: outside the tolerance too.
    let b_first = &tables[2][0];
    assert!(b_first[3].failing && b_first[4].failing, "{b_first:?}");
}

#[test]
fn charts_label_parts_by_serial_and_date_and_mark_what_is_outside() {
    let (rows, html) = page();
    let charts = svgs(&html);
    assert_eq!(charts.len(), rows.len(), "a chart per profile");
    let (a, b) = (charts[0], charts[1]);
    for k in 1..=PARTS {
        let label = format!("SN-{k}  2026-11-{k:02} 08:30");
        assert!(a.contains(&label), "{label} on the abscissa");
    }
    // No fractional ticks: the only abscissa labels are the parts'.
    assert!(!a.contains(">\n0.5\n<") && !a.contains(">\n1.5\n<"));
    // Red dots: one for A's part 12, two per part for B (both extremes above the band).
    let red = |svg: &str| svg.matches("fill=\"#C8001E\"").count();
    assert_eq!(red(a), 1 + 1, "A's outlier, and the legend's sample");
    assert_eq!(red(b), 2 * PARTS + 1);
    // A ring for each of A's parts 8 to 12 (and the legend's); none on B.
    let rings = |svg: &str| svg.matches(&format!("r=\"{RING}\"")).count();
    assert_eq!((rings(a), rings(b)), (5 + 1, 1));
    // The control limits: each extreme's, as dashes, in its colour.
    for colour in ["#D55E00", "#0072B2"] {
        assert!(
            a.matches(&format!("stroke=\"{colour}\"")).count() > 20,
            "{colour} dashes"
        );
    }
    assert!(a.contains("control limits") && a.contains("min/max envelope"));
}

/// The ring's radius as the SVG writes it.
const RING: &str = "9";

#[test]
fn the_page_states_what_is_computed_and_warns_of_a_short_history() {
    let (_, html) = page();
    for words in [
        "the largest deviation of its points",
        "Cpk</b> = min(CPU, CPL)",
        "2.66 &times; the mean moving range",
        "12 parts in the history",
    ] {
        assert!(html.contains(words), "{words}");
    }
}

#[test]
fn control_limits_need_two_parts_and_long_histories_label_every_kth_part() {
    let one = trend(&[record(0, "A", -0.05, 0.05)], LOWER, UPPER);
    let svg = crate::report::trend_chart::trend_svg(&one[0], LOWER, UPPER).unwrap();
    // The run, and the legend's samples (a line, the centre line, three dashes): no centre line, no limits.
    assert_eq!(svg.matches("stroke=\"#D55E00\"").count(), 1 + 5);
    // 60 parts: every 3rd labelled (at most 25 labels), starting with the first.
    let long: Vec<ProfileRecord> = (0..60).map(|k| record(k, "A", -0.05, 0.05)).collect();
    let rows = trend(&long, LOWER, UPPER);
    let svg = crate::report::trend_chart::trend_svg(&rows[0], LOWER, UPPER).unwrap();
    let labelled: Vec<usize> = (1..=60)
        .filter(|k| svg.contains(&format!(">\nSN-{k}  ")))
        .collect();
    assert_eq!(labelled, (1..=60).step_by(3).collect::<Vec<_>>());
}

#[test]
fn blade_parameters_get_a_table_of_their_capability_after_the_profiles() {
    // B r100's chord over the twelve parts: +0.01 mm but for part 12, 0.09 mm long (outside -0.05 .. +0.05 mm).
    let parameters: Vec<ParameterRecord> = (0..PARTS)
        .map(|k| {
            let deviation = if k == PARTS - 1 { 0.09 } else { 0.01 };
            ParameterRecord {
                serial: format!("SN-{}", k + 1),
                finished: format!("2026-11-{:02}T08:30:00Z", k + 1),
                instance: "B".into(),
                profile: "r100".into(),
                parameter: "chord_mm".into(),
                nominal: 172.85,
                measured: 172.85 + deviation,
                deviation,
                limits: Some((-0.05, 0.05)),
                passed: Some(deviation <= 0.05),
            }
        })
        .collect();
    let parameter_rows = parameter_trend(&parameters);
    let rows = trend(&history(), LOWER, UPPER);
    let html = trend_page("propeller", &rows, &parameter_rows, LOWER, UPPER).unwrap();
    let tables = tables(&html);
    assert_eq!(tables.len(), 2 + rows.len());
    let chord = &tables[1][0];
    // Mean 0.0166667 mm, s = 0.08 / sqrt(12) = 0.0230940: Cp = 0.1 / 0.138564 = 0.72, Cpk = 0.0333 / 0.069282
    // = 0.48, both failing; part 12 breaks the control limit (centre + 2.66 x 0.08 / 11 = 0.0360 mm) and parts 8
    // to 11 the run rule (the eleven before it all below the centre): five parts signalled.
    assert_eq!(
        texts(chord),
        [
            "B r100",
            "chord_mm",
            "12",
            "1",
            "+0.0167 mm",
            "0.0231 mm",
            "-0.0500 .. +0.0500 mm",
            "0.72",
            "0.48",
            "5"
        ]
    );
    assert!(chord[3].failing && chord[7].failing && chord[8].failing && chord[9].failing);
}
