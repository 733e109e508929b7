//! A job's folder on disk: its record, and every profile scanned for it. This is what makes a job survive a
//! fault or a killed daemon: a profile counts as done only once its scan file exists (written to a temporary name
//! and renamed), and the points of the profile being scanned are appended to a partial file as they arrive, so
//! that a scan cut short is kept for the record and tells the station where the probe was.
//!
//! ```text
//! DATA/jobs/JOB/job.json                      the record: kind, part, serial, state
//! DATA/jobs/JOB/scans/A-r100.json             a complete profile scan (raw points, machine, ball radius)
//! DATA/jobs/JOB/scans/A-r200.partial.jsonl    the profile being scanned: a header line, then a point per line
//! DATA/jobs/JOB/scans/A-r200.cut-1700000000000.jsonl   a scan cut short, set aside when the profile restarts
//! ```

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufRead, BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::analysis::RawPoint;
use crate::api::{JobKind, ScanRef};
use crate::fsutil::write_atomically;

/// What a job is and how it ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobRecord {
    pub id: String,
    pub kind: JobKind,
    pub part: String,
    pub serial: Option<String>,
    pub started: String,
    pub state: JobState,
    /// The folder of the inspection's report, once written.
    pub report: Option<PathBuf>,
    /// Profiles scanned again because their scan had a hole (absent from older records).
    #[serde(default)]
    pub rescans: Vec<crate::report::Rescan>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "state", rename_all = "snake_case")]
pub enum JobState {
    /// Running, or stopped by a fault or a killed daemon: it resumes from its complete profiles.
    Open,
    Finished,
    Aborted,
    Failed {
        error: String,
    },
}

/// Who scanned a profile, with what, and when.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScanHeader {
    pub machine: String,
    pub ball_radius_mm: f64,
    pub started: String,
}

/// A complete profile scan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScanFile {
    #[serde(flatten)]
    pub header: ScanHeader,
    pub finished: String,
    /// The raw points in the order measured: ball centres and normals, machine coordinates, mm.
    pub points: Vec<RawPoint>,
}

/// A job's folder.
#[derive(Debug, Clone)]
pub struct JobDir {
    root: PathBuf,
}

impl JobDir {
    /// Creates the folder of a new job under `data`/jobs and writes its record.
    pub fn create(data: &Path, record: &JobRecord) -> io::Result<JobDir> {
        let root = data.join("jobs").join(&record.id);
        fs::create_dir_all(root.join("scans")).map_err(|e| {
            io::Error::new(e.kind(), format!("cannot create {}: {e}", root.display()))
        })?;
        let dir = JobDir { root };
        dir.save_record(record)?;
        Ok(dir)
    }

    pub fn path(&self) -> &Path {
        &self.root
    }

    pub fn record(&self) -> io::Result<JobRecord> {
        read_json(&self.root.join("job.json"))
    }

    pub fn save_record(&self, record: &JobRecord) -> io::Result<()> {
        let json = serde_json::to_vec_pretty(record).expect("a record serialises");
        write_atomically(&self.root.join("job.json"), &json)
    }

    /// The profiles whose scans are complete on disk: each scan file as its check (`*.check.json`, written
    /// after the scan file was read back) recorded it, byte for byte, and whole. A scan file that fails this (cut
    /// short, changed, its check missing) is set aside, kept, and its profile counts as not done.
    pub fn completed(&self) -> io::Result<Vec<String>> {
        let mut names = Vec::new();
        for entry in fs::read_dir(self.root.join("scans"))? {
            let name = entry?.file_name().to_string_lossy().into_owned();
            let Some(stem) = name.strip_suffix(".json") else {
                continue;
            };
            if stem.ends_with(".check") {
                continue;
            }
            match self.verify(stem) {
                Ok(()) => names.push(stem.to_string()),
                Err(problem) => {
                    tracing::error!(scan = stem, %problem, "a scan file on disk is not whole; its profile is scanned again");
                    self.set_aside(stem, "bad")?;
                }
            }
        }
        names.sort();
        Ok(names)
    }

    /// Whether the scan file `stem` is the one its check recorded, and reads back whole.
    fn verify(&self, stem: &str) -> Result<(), String> {
        let scans = self.root.join("scans");
        let bytes = fs::read(scans.join(format!("{stem}.json"))).map_err(|e| e.to_string())?;
        let check: ScanCheck = read_json(&scans.join(format!("{stem}.check.json")))
            .map_err(|e| format!("its check: {e}"))?;
        let found = ScanCheck::of(&bytes, check.points);
        if found != check {
            return Err(format!(
                "{} bytes with checksum {:08x}, its check recorded {} bytes with checksum {:08x}",
                found.bytes, found.crc32, check.bytes, check.crc32
            ));
        }
        let file: ScanFile = serde_json::from_slice(&bytes).map_err(|e| e.to_string())?;
        if file.points.len() != check.points {
            return Err(format!(
                "{} points, its check recorded {}",
                file.points.len(),
                check.points
            ));
        }
        Ok(())
    }

    /// Renames a scan file and its check out of the way (kept: nothing measured is deleted).
    fn set_aside(&self, stem: &str, why: &str) -> io::Result<()> {
        let scans = self.root.join("scans");
        let stamp = crate::station::clock::unix_ms();
        for suffix in ["json", "check.json"] {
            let path = scans.join(format!("{stem}.{suffix}"));
            if path.exists() {
                fs::rename(
                    &path,
                    scans.join(format!("{stem}.{why}-{stamp}.{suffix}.kept")),
                )?;
            }
        }
        Ok(())
    }

    /// Writes a complete scan (atomically), reads it back, writes its check, then removes its partial file: from
    /// here on it counts as done.
    pub fn write_scan(&self, scan: &ScanRef, file: &ScanFile) -> io::Result<()> {
        let json = serde_json::to_vec(file).expect("a scan serialises");
        let path = self.scan_path(scan);
        write_atomically(&path, &json)?;
        let back = fs::read(&path)?;
        let check = ScanCheck::of(&json, file.points.len());
        if ScanCheck::of(&back, file.points.len()) != check {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{} does not read back as written", path.display()),
            ));
        }
        let stem = file_stem(scan);
        let check_path = self.root.join("scans").join(format!("{stem}.check.json"));
        write_atomically(
            &check_path,
            &serde_json::to_vec(&check).expect("a check serialises"),
        )?;
        match fs::remove_file(self.partial_path(scan)) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        }
    }

    pub fn read_scan(&self, scan: &ScanRef) -> io::Result<ScanFile> {
        read_json(&self.scan_path(scan))
    }

    /// Starts the partial file of a profile about to be scanned; a partial file left by an earlier attempt is
    /// set aside first, never overwritten.
    pub fn start_partial(&self, scan: &ScanRef, header: &ScanHeader) -> io::Result<PartialScan> {
        self.set_aside_partial(scan)?;
        let path = self.partial_path(scan);
        let mut file = OpenOptions::new()
            .create_new(true)
            .append(true)
            .open(&path)
            .map_err(|e| {
                io::Error::new(e.kind(), format!("cannot create {}: {e}", path.display()))
            })?;
        writeln!(
            file,
            "{}",
            serde_json::to_string(header).expect("a header serialises")
        )?;
        Ok(PartialScan {
            file: BufWriter::new(file),
            path,
        })
    }

    /// The points of a profile's partial file, if one is there (the scan that was running when the job stopped).
    pub fn read_partial(&self, scan: &ScanRef) -> io::Result<Option<(ScanHeader, Vec<RawPoint>)>> {
        let path = self.partial_path(scan);
        let file = match File::open(&path) {
            Ok(file) => file,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(e),
        };
        let mut lines = BufReader::new(file).lines();
        let Some(header) = lines.next().transpose()? else {
            return Ok(None);
        };
        let header: ScanHeader = serde_json::from_str(&header).map_err(|e| bad_data(&path, e))?;
        let mut points = Vec::new();
        for line in lines {
            let line = line?;
            // A line cut by a kill mid-write is the only one that can be incomplete: the last.
            match serde_json::from_str(&line) {
                Ok(point) => points.push(point),
                Err(_) => break,
            }
        }
        Ok(Some((header, points)))
    }

    /// Renames a partial file out of the way (kept: nothing measured is deleted).
    pub fn set_aside_partial(&self, scan: &ScanRef) -> io::Result<()> {
        let path = self.partial_path(scan);
        if !path.exists() {
            return Ok(());
        }
        let stamp = crate::station::clock::unix_ms();
        let aside = self
            .root
            .join("scans")
            .join(format!("{}.cut-{stamp}.jsonl", file_stem(scan)));
        fs::rename(&path, &aside)
    }

    /// Every profile with a partial file.
    pub fn partial_scans(&self) -> io::Result<Vec<String>> {
        let mut names = Vec::new();
        for entry in fs::read_dir(self.root.join("scans"))? {
            let name = entry?.file_name().to_string_lossy().into_owned();
            if let Some(stem) = name.strip_suffix(".partial.jsonl") {
                names.push(stem.to_string());
            }
        }
        Ok(names)
    }

    fn scan_path(&self, scan: &ScanRef) -> PathBuf {
        self.root
            .join("scans")
            .join(format!("{}.json", file_stem(scan)))
    }

    fn partial_path(&self, scan: &ScanRef) -> PathBuf {
        self.root
            .join("scans")
            .join(format!("{}.partial.jsonl", file_stem(scan)))
    }
}

/// The points of a profile being scanned, appended as they arrive.
pub struct PartialScan {
    file: BufWriter<File>,
    path: PathBuf,
}

impl PartialScan {
    /// Appends one point to the buffer; [`PartialScan::flush`] hands what was appended to the operating system.
    pub fn push(&mut self, point: &RawPoint) -> io::Result<()> {
        serde_json::to_writer(&mut self.file, point)
            .map_err(io::Error::from)
            .and_then(|()| self.file.write_all(b"\n"))
            .map_err(|e| self.error(e))
    }

    /// Hands the appended points to the operating system, so that a killed daemon keeps them.
    pub fn flush(&mut self) -> io::Result<()> {
        self.file.flush().map_err(|e| self.error(e))
    }

    fn error(&self, e: io::Error) -> io::Error {
        io::Error::new(
            e.kind(),
            format!("cannot write {}: {e}", self.path.display()),
        )
    }
}

/// What a complete scan file was when written: its length, its CRC-32 and its point count.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
struct ScanCheck {
    points: usize,
    bytes: usize,
    crc32: u32,
}

impl ScanCheck {
    fn of(bytes: &[u8], points: usize) -> ScanCheck {
        ScanCheck {
            points,
            bytes: bytes.len(),
            crc32: crc32fast::hash(bytes),
        }
    }
}

/// The file name of a profile's scan: instance and profile names joined.
pub fn file_stem(scan: &ScanRef) -> String {
    format!("{}-{}", scan.instance, scan.profile)
}

/// Jobs under `data` that were left open (stopped by a fault or a killed daemon), oldest first.
pub fn open_jobs(data: &Path) -> io::Result<Vec<(JobDir, JobRecord)>> {
    let jobs = data.join("jobs");
    let mut open = Vec::new();
    let entries = match fs::read_dir(&jobs) {
        Ok(entries) => entries,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(open),
        Err(e) => return Err(e),
    };
    for entry in entries {
        let dir = JobDir {
            root: entry?.path(),
        };
        if let Ok(record) = dir.record() {
            if record.state == JobState::Open {
                open.push((dir, record));
            }
        }
    }
    open.sort_by(|a, b| a.1.started.cmp(&b.1.started));
    Ok(open)
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> io::Result<T> {
    let text = fs::read_to_string(path)
        .map_err(|e| io::Error::new(e.kind(), format!("cannot read {}: {e}", path.display())))?;
    serde_json::from_str(&text).map_err(|e| bad_data(path, e))
}

fn bad_data(path: &Path, e: serde_json::Error) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{}: {e}", path.display()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> JobRecord {
        JobRecord {
            id: "propeller-SN1-1".into(),
            kind: JobKind::Inspect,
            part: "propeller".into(),
            serial: Some("SN1".into()),
            started: "2026-11-23T10:00:00Z".into(),
            state: JobState::Open,
            report: None,
            rescans: Vec::new(),
        }
    }

    fn point(x: f64) -> RawPoint {
        RawPoint {
            centre: [x, 1.0, 2.0],
            normal: [0.0, 0.0, 1.0],
            quality: 0.0,
        }
    }

    fn header() -> ScanHeader {
        ScanHeader {
            machine: "cmm1".into(),
            ball_radius_mm: 1.0,
            started: "t".into(),
        }
    }

    fn scan_ref(instance: &str, profile: &str) -> ScanRef {
        ScanRef {
            instance: instance.into(),
            profile: profile.into(),
        }
    }

    #[test]
    fn a_profile_counts_as_done_only_once_its_scan_file_is_written() {
        let data = tempfile::tempdir().unwrap();
        let dir = JobDir::create(data.path(), &record()).unwrap();
        let scan = scan_ref("B", "r300");
        let header = header();
        let mut partial = dir.start_partial(&scan, &header).unwrap();
        partial.push(&point(1.0)).unwrap();
        partial.push(&point(2.0)).unwrap();
        partial.flush().unwrap();
        assert!(dir.completed().unwrap().is_empty());
        let (read_header, points) = dir.read_partial(&scan).unwrap().unwrap();
        assert_eq!((read_header, points.len()), (header.clone(), 2));
        assert_eq!(open_jobs(data.path()).unwrap().len(), 1);

        // A second attempt sets the first aside instead of losing it.
        let mut again = dir.start_partial(&scan, &header).unwrap();
        again.push(&point(3.0)).unwrap();
        let kept = fs::read_dir(dir.path().join("scans"))
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .contains(".cut-")
            })
            .count();
        assert_eq!(kept, 1);

        let file = ScanFile {
            header,
            finished: "t2".into(),
            points: vec![point(3.0)],
        };
        dir.write_scan(&scan, &file).unwrap();
        assert_eq!(dir.completed().unwrap(), vec!["B-r300".to_string()]);
        assert!(dir.read_partial(&scan).unwrap().is_none());
        assert_eq!(dir.read_scan(&scan).unwrap(), file);
    }

    #[test]
    fn a_scan_file_cut_short_changed_or_without_its_check_is_not_done_and_is_kept_aside() {
        let data = tempfile::tempdir().unwrap();
        let dir = JobDir::create(data.path(), &record()).unwrap();
        let scans = dir.path().join("scans");
        let file = ScanFile {
            header: header(),
            finished: "t2".into(),
            points: (0..50).map(|i| point(i as f64)).collect(),
        };
        for (instance, spoil) in [("A", 0), ("B", 1), ("C", 2), ("D", 3)] {
            let scan = scan_ref(instance, "r100");
            dir.write_scan(&scan, &file).unwrap();
            let path = scans.join(format!("{instance}-r100.json"));
            let bytes = fs::read(&path).unwrap();
            match spoil {
                // Cut short, as a full disk or a crash of the file system leaves it.
                1 => fs::write(&path, &bytes[..bytes.len() / 2]).unwrap(),
                // One digit changed: the same length, another checksum.
                2 => {
                    let text = String::from_utf8(bytes).unwrap().replacen("17", "18", 1);
                    fs::write(&path, text).unwrap();
                }
                3 => fs::remove_file(scans.join(format!("{instance}-r100.check.json"))).unwrap(),
                _ => {}
            }
        }
        assert_eq!(dir.completed().unwrap(), vec!["A-r100".to_string()]);
        // The bad ones are kept beside, and are not read as scans again.
        let kept = fs::read_dir(&scans)
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .contains(".bad-")
            })
            .count();
        assert_eq!(
            kept,
            3 + 2,
            "three scan files and the two checks that remained"
        );
        assert_eq!(dir.completed().unwrap(), vec!["A-r100".to_string()]);
    }

    #[test]
    fn a_line_cut_by_a_kill_is_dropped_and_the_rest_kept() {
        let data = tempfile::tempdir().unwrap();
        let dir = JobDir::create(data.path(), &record()).unwrap();
        let scan = scan_ref("A", "r100");
        let header = header();
        let mut partial = dir.start_partial(&scan, &header).unwrap();
        partial.push(&point(1.0)).unwrap();
        partial.file.write_all(b"{\"centre\":[1.0,").unwrap();
        partial.flush().unwrap();
        let (_, points) = dir.read_partial(&scan).unwrap().unwrap();
        assert_eq!(points, vec![point(1.0)]);
    }
}
