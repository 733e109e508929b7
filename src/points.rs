//! Point files: CSV with a header, `y,z` for a planar profile or `x,y,z` for 3-D points, in millimetres, and
//! `x,y,z,segment` for 3-D points of a segmented part.
//! Every problem is reported with the file and the line, so an operator can find it in an editor.

use std::path::{Path, PathBuf};

use nalgebra::{Vector2, Vector3};

/// The points of one file, in file order.
#[derive(Debug, Clone, PartialEq)]
pub enum PointSet {
    /// (y, z) points of a planar profile.
    Profile(Vec<Vector2<f64>>),
    /// (x, y, z) points.
    Spatial(Vec<Vector3<f64>>),
}

impl PointSet {
    pub fn len(&self) -> usize {
        match self {
            Self::Profile(p) => p.len(),
            Self::Spatial(p) => p.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A problem with a point file: the file, the line (1 is the header) when one line is at fault, and what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{}: {problem}", path.display(), line.map(|l| format!(": line {l}")).unwrap_or_default())]
pub struct PointFileError {
    pub path: PathBuf,
    pub line: Option<u64>,
    pub problem: String,
}

impl PointFileError {
    pub fn new(path: &Path, line: Option<u64>, problem: impl Into<String>) -> Self {
        Self {
            path: path.to_path_buf(),
            line,
            problem: problem.into(),
        }
    }
}

const HEADER_HELP: &str = "expected a header of y,z (a profile) or x,y,z (3-D points), in mm";

/// Reads a point file.
pub fn read_points(path: &Path) -> Result<PointSet, PointFileError> {
    read_point_file(path).map(|file| file.points)
}

/// A point file's points and, for each, the line of the file it is on (to name a point to the operator).
pub struct PointFile {
    pub points: PointSet,
    pub lines: Vec<u64>,
}

/// Reads a point file, keeping each point's line.
pub fn read_point_file(path: &Path) -> Result<PointFile, PointFileError> {
    let table = read_table(path, |header| {
        if let Some(unknown) = header.iter().find(|c| !["x", "y", "z"].contains(c)) {
            let hint = if *unknown == SEGMENT_COLUMN {
                "; a segment column is read by `zeroset fit supershape`"
            } else {
                ""
            };
            return Err(format!("unknown column '{unknown}' ({HEADER_HELP}{hint})"));
        }
        match header {
            ["y", "z"] | ["x", "y", "z"] => Ok(()),
            _ => Err(format!("header '{}' ({HEADER_HELP})", header.join(","))),
        }
    })?;
    let spatial = table.header.len() == 3;
    let lines = table
        .rows
        .iter()
        .map(|(line, _)| line.unwrap_or_default())
        .collect();
    let rows = table
        .rows
        .iter()
        .map(|(line, record)| table.coordinates(*line, record, table.header.len()))
        .collect::<Result<Vec<Vec<f64>>, _>>()?;
    let points = if spatial {
        PointSet::Spatial(
            rows.iter()
                .map(|r| Vector3::new(r[0], r[1], r[2]))
                .collect(),
        )
    } else {
        PointSet::Profile(rows.iter().map(|r| Vector2::new(r[0], r[1])).collect())
    };
    Ok(PointFile { points, lines })
}

/// The column that names a section's points that are contacts of the ball rolling round a sharp edge (1; 0 for
/// the others): the station takes their mean for the edge's apex.
pub const ROLL_COLUMN: &str = "roll";

/// One measured section: its (y, z) points in order round it, and which of them are contacts of the ball rolling
/// round a sharp edge.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionPoints {
    pub points: Vec<Vector2<f64>>,
    /// Indices into `points`.
    pub roll_contacts: Vec<usize>,
}

/// Reads a section, `y,z` (no roll contacts named) or `y,z,roll` (as the station writes each section of a report
/// under `sections/`).
pub fn read_section(path: &Path) -> Result<SectionPoints, PointFileError> {
    let table = read_table(path, |header| {
        match header {
        ["y", "z"] | ["y", "z", ROLL_COLUMN] => Ok(()),
        ["x", "y", "z"] => Err("this file has x,y,z; a section is y,z points in its plane".into()),
        _ => Err(format!(
            "header '{}' (expected y,z or y,z,{ROLL_COLUMN}: a section's points in mm, and 1 where a point is a \
             contact of the ball rolling round a sharp edge)",
            header.join(",")
        )),
    }
    })?;
    let mut section = SectionPoints {
        points: Vec::with_capacity(table.rows.len()),
        roll_contacts: Vec::new(),
    };
    for (index, (line, record)) in table.rows.iter().enumerate() {
        let yz = table.coordinates(*line, record, 2)?;
        section.points.push(Vector2::new(yz[0], yz[1]));
        match record.get(2) {
            None | Some("0") => {}
            Some("1") => section.roll_contacts.push(index),
            Some(other) => {
                return Err(table.error(
                    *line,
                    format!("column {ROLL_COLUMN}: '{other}' is neither 0 nor 1"),
                ))
            }
        }
    }
    Ok(section)
}

/// The column that names the segment of a part a point belongs to (seed 001 section 6.3: a segmented scan).
pub const SEGMENT_COLUMN: &str = "segment";

/// The 3-D points of one segment of a part.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// The segment's name from the file; empty for a file without a segment column.
    pub label: String,
    pub points: Vec<Vector3<f64>>,
}

/// Reads 3-D points, `x,y,z` (one unnamed segment) or `x,y,z,segment` (the segments in the order they first
/// appear, each with its points in file order).
pub fn read_segments(path: &Path) -> Result<Vec<Segment>, PointFileError> {
    let table = read_table(path, |header| match header {
        ["x", "y", "z"] | ["x", "y", "z", SEGMENT_COLUMN] => Ok(()),
        _ => {
            let hint = if header == ["y", "z"] {
                "; y,z is a planar profile, and this needs points over a part's surface"
            } else {
                ""
            };
            Err(format!(
                "header '{}' (expected x,y,z or x,y,z,{SEGMENT_COLUMN}: 3-D points in mm, with the segment of the \
                 part each belongs to{hint})",
                header.join(",")
            ))
        }
    })?;
    let mut segments: Vec<Segment> = Vec::new();
    for (line, record) in &table.rows {
        let r = table.coordinates(*line, record, 3)?;
        let label = record.get(3).unwrap_or_default();
        if table.header.len() == 4 && label.is_empty() {
            return Err(table.error(*line, format!("column {SEGMENT_COLUMN}: no segment named")));
        }
        let point = Vector3::new(r[0], r[1], r[2]);
        match segments.iter_mut().find(|s| s.label == label) {
            Some(segment) => segment.points.push(point),
            None => segments.push(Segment {
                label: label.to_string(),
                points: vec![point],
            }),
        }
    }
    Ok(segments)
}

/// A point file's header and records, each record with its line and as many fields as the header.
struct Table {
    path: PathBuf,
    header: Vec<String>,
    rows: Vec<(Option<u64>, csv::StringRecord)>,
}

impl Table {
    fn error(&self, line: Option<u64>, problem: impl Into<String>) -> PointFileError {
        PointFileError::new(&self.path, line, problem)
    }

    /// The first `count` fields of a record as coordinates.
    fn coordinates(
        &self,
        line: Option<u64>,
        record: &csv::StringRecord,
        count: usize,
    ) -> Result<Vec<f64>, PointFileError> {
        record
            .iter()
            .zip(&self.header)
            .take(count)
            .map(|(field, column)| parse_coordinate(field, column).map_err(|p| self.error(line, p)))
            .collect()
    }
}

/// Reads a point file whose header `check_header` accepts (or says why not, as the problem of line 1) before
/// any record is read.
fn read_table(
    path: &Path,
    check_header: impl FnOnce(&[&str]) -> Result<(), String>,
) -> Result<Table, PointFileError> {
    let file = std::fs::File::open(path)
        .map_err(|e| PointFileError::new(path, None, format!("cannot open: {e}")))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .from_reader(file);
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| PointFileError::new(path, Some(1), format!("unreadable header: {e}")))?
        .iter()
        .map(str::to_string)
        .collect();
    let columns: Vec<&str> = header.iter().map(String::as_str).collect();
    check_header(&columns).map_err(|problem| PointFileError::new(path, Some(1), problem))?;
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map(|p| p.line());
            PointFileError::new(path, line, format!("{e}"))
        })?;
        let line = record.position().map(|p| p.line());
        if record.len() != header.len() {
            return Err(PointFileError::new(
                path,
                line,
                format!("{} fields, the header has {}", record.len(), header.len()),
            ));
        }
        rows.push((line, record));
    }
    if rows.is_empty() {
        return Err(PointFileError::new(
            path,
            None,
            "no points after the header",
        ));
    }
    Ok(Table {
        path: path.to_path_buf(),
        header,
        rows,
    })
}

fn parse_coordinate(field: &str, column: &str) -> Result<f64, String> {
    let value: f64 = field
        .parse()
        .map_err(|_| format!("column {column}: '{field}' is not a number"))?;
    if !value.is_finite() {
        return Err(format!("column {column}: '{field}' is not a finite number"));
    }
    if value.abs() > REACH_MM {
        return Err(format!(
            "column {column}: {field} mm is beyond any measuring machine's reach ({REACH_MM} mm); a unit or \
             export error? correct or remove the line"
        ));
    }
    Ok(value)
}

/// No coordinate measuring machine reaches farther than this from its origin (mm): 100 m.
const REACH_MM: f64 = 1e5;

#[cfg(test)]
mod tests {
    use super::*;

    /// What `reader` makes of `text` written to DIR/points.csv, its error with the folder named DIR.
    fn read_as<T>(
        text: &str,
        reader: impl Fn(&Path) -> Result<T, PointFileError>,
    ) -> Result<T, String> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("points.csv");
        std::fs::write(&path, text).unwrap();
        reader(&path).map_err(|e| {
            e.to_string()
                .replace(&dir.path().display().to_string(), "DIR")
        })
    }

    fn read(text: &str) -> Result<PointSet, String> {
        read_as(text, read_points)
    }

    #[test]
    fn reads_profiles_and_spatial_points() {
        assert_eq!(
            read("y,z\n1,2\n3.5, -4e-1\n").unwrap(),
            PointSet::Profile(vec![Vector2::new(1.0, 2.0), Vector2::new(3.5, -0.4)])
        );
        assert_eq!(
            read("x,y,z\n1,2,3\n").unwrap(),
            PointSet::Spatial(vec![Vector3::new(1.0, 2.0, 3.0)])
        );
    }

    #[test]
    fn every_problem_names_the_file_and_the_line() {
        assert_eq!(
            read("y,z\n1,2\n3,abc\n").unwrap_err(),
            "DIR/points.csv: line 3: column z: 'abc' is not a number"
        );
        assert_eq!(
            read("y,z\n1,NaN\n").unwrap_err(),
            "DIR/points.csv: line 2: column z: 'NaN' is not a finite number"
        );
        // A value no machine can measure names its line (it used to make the whole file "a straight line").
        let far = read("y,z\n1,2\n3,4\n1e30,5\n").unwrap_err();
        assert!(
            far.starts_with(
                "DIR/points.csv: line 4: column y: 1e30 mm is beyond any measuring machine's reach"
            ),
            "{far}"
        );
        assert!(read("y,z\n-99999,2\n").is_ok(), "100 m is within reach");
        assert_eq!(
            read("y,w\n1,2\n").unwrap_err(),
            "DIR/points.csv: line 1: unknown column 'w' (expected a header of y,z (a profile) or x,y,z (3-D points), in mm)"
        );
        assert!(read("z,y\n1,2\n")
            .unwrap_err()
            .contains("line 1: header 'z,y'"));
        assert_eq!(
            read("y,z\n").unwrap_err(),
            "DIR/points.csv: no points after the header"
        );
        assert!(read("y,z\n1,2\n1,2,3\n")
            .unwrap_err()
            .starts_with("DIR/points.csv: line 3:"));
        assert!(
            read("y,w\n")
                .unwrap_err()
                .contains("line 1: unknown column 'w'"),
            "a bad header is told before the missing points"
        );
        assert!(read("x,y,z,segment\n1,2,3,a\n")
            .unwrap_err()
            .ends_with("a segment column is read by `zeroset fit supershape`)"));
        let missing = read_points(Path::new("/no/such/points.csv"))
            .unwrap_err()
            .to_string();
        assert!(
            missing.starts_with("/no/such/points.csv: cannot open"),
            "{missing}"
        );
    }

    fn segments(text: &str) -> Result<Vec<Segment>, String> {
        read_as(text, read_segments)
    }

    /// Segments come in the order they first appear, each with its points in file order; a file without the
    /// column is one unnamed segment.
    #[test]
    fn reads_segments_in_order() {
        let read = segments("x,y,z,segment\n1,2,3,body\n4,5,6,boss\n7,8,9,body\n").unwrap();
        assert_eq!(
            read,
            vec![
                Segment {
                    label: "body".into(),
                    points: vec![Vector3::new(1.0, 2.0, 3.0), Vector3::new(7.0, 8.0, 9.0)]
                },
                Segment {
                    label: "boss".into(),
                    points: vec![Vector3::new(4.0, 5.0, 6.0)]
                },
            ]
        );
        let one = segments("x,y,z\n1,2,3\n").unwrap();
        assert_eq!(one.len(), 1);
        assert_eq!(one[0].label, "");
        assert_eq!(
            segments("x,y,z,segment\n1,2,3,\n").unwrap_err(),
            "DIR/points.csv: line 2: column segment: no segment named"
        );
        assert_eq!(
            segments("x,y,z,segment\n1,2,q,a\n").unwrap_err(),
            "DIR/points.csv: line 2: column z: 'q' is not a number"
        );
        assert!(segments("y,z\n1,2\n")
            .unwrap_err()
            .contains("line 1: header 'y,z' (expected x,y,z or x,y,z,segment"));
        assert!(segments("y,z\n1,2\n")
            .unwrap_err()
            .ends_with("y,z is a planar profile, and this needs points over a part's surface)"));
    }

    #[test]
    fn a_section_names_its_roll_contacts_by_their_place_in_the_file() {
        let section = |text: &str| read_as(text, read_section);
        let read = section("y,z,roll\n1,2,0\n3,4,1\n5,6,1\n7,8,0\n").unwrap();
        assert_eq!(read.points[2], Vector2::new(5.0, 6.0));
        assert_eq!(read.roll_contacts, vec![1, 2]);
        let plain = section("y,z\n1,2\n3,4\n").unwrap();
        assert_eq!(plain.points.len(), 2);
        assert!(plain.roll_contacts.is_empty());
        assert_eq!(
            section("y,z,roll\n1,2,0\n3,4,yes\n").unwrap_err(),
            "DIR/points.csv: line 3: column roll: 'yes' is neither 0 nor 1"
        );
        assert_eq!(
            section("x,y,z\n1,2,3\n").unwrap_err(),
            "DIR/points.csv: line 1: this file has x,y,z; a section is y,z points in its plane"
        );
    }
}
