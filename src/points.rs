//! Point files: CSV with a header, `y,z` for a planar profile or `x,y,z` for 3-D points, in millimetres.
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
    if let Some(unknown) = header
        .iter()
        .find(|c| !["x", "y", "z"].contains(&c.as_str()))
    {
        return Err(PointFileError::new(
            path,
            Some(1),
            format!("unknown column '{unknown}' ({HEADER_HELP})"),
        ));
    }
    let spatial = match header
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>()
        .as_slice()
    {
        ["y", "z"] => false,
        ["x", "y", "z"] => true,
        _ => {
            return Err(PointFileError::new(
                path,
                Some(1),
                format!("header '{}' ({HEADER_HELP})", header.join(",")),
            ))
        }
    };
    let mut rows: Vec<Vec<f64>> = Vec::new();
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
        let values = record
            .iter()
            .zip(&header)
            .map(|(field, column)| {
                parse_coordinate(field, column).map_err(|p| PointFileError::new(path, line, p))
            })
            .collect::<Result<Vec<f64>, _>>()?;
        rows.push(values);
    }
    if rows.is_empty() {
        return Err(PointFileError::new(
            path,
            None,
            "no points after the header",
        ));
    }
    Ok(if spatial {
        PointSet::Spatial(
            rows.iter()
                .map(|r| Vector3::new(r[0], r[1], r[2]))
                .collect(),
        )
    } else {
        PointSet::Profile(rows.iter().map(|r| Vector2::new(r[0], r[1])).collect())
    })
}

fn parse_coordinate(field: &str, column: &str) -> Result<f64, String> {
    let value: f64 = field
        .parse()
        .map_err(|_| format!("column {column}: '{field}' is not a number"))?;
    if !value.is_finite() {
        return Err(format!("column {column}: '{field}' is not a finite number"));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<PointSet, String> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("points.csv");
        std::fs::write(&path, text).unwrap();
        read_points(&path).map_err(|e| {
            e.to_string()
                .replace(&dir.path().display().to_string(), "DIR")
        })
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
        let missing = read_points(Path::new("/no/such/points.csv"))
            .unwrap_err()
            .to_string();
        assert!(
            missing.starts_with("/no/such/points.csv: cannot open"),
            "{missing}"
        );
    }
}
