//! A job's recorder: the one thread that writes its scans to disk. Every point goes to its profile's partial file
//! as it comes (a killed daemon keeps it); a finished profile's scan file is written and flushed, and only then is
//! the profile announced done and counted. Opening files and flushing them to the disk take milliseconds, which
//! the live deviations must not wait for, so none of it happens on the analysis task.

use std::collections::HashMap;

use tokio::sync::{broadcast, mpsc};

use super::clock;
use super::journal::{JobDir, PartialScan, ScanFile, ScanHeader};
use super::DaemonMsg;
use crate::analysis::stats::{DeviationStats, Verdict};
use crate::analysis::RawPoint;
use crate::api::{Event, ScanRef};
use crate::plan::ProfileKey;

/// What the analysis asks the recorder to write, in the order the points came.
pub enum Record {
    Start {
        key: ProfileKey,
        scan: ScanRef,
        header: ScanHeader,
    },
    Point {
        key: ProfileKey,
        raw: RawPoint,
    },
    /// The scan completed: its points, and what to announce once they are on disk.
    End {
        key: ProfileKey,
        points: Vec<RawPoint>,
        stats: Option<DeviationStats>,
        verdict: Option<Verdict>,
    },
    /// The scan was cut short: its partial file stays.
    Cut {
        key: ProfileKey,
    },
}

/// Where the recorder reports.
pub struct Recorder {
    pub job: String,
    pub dir: JobDir,
    pub events: broadcast::Sender<Event>,
    pub daemon: mpsc::Sender<DaemonMsg>,
}

struct Open {
    scan: ScanRef,
    header: ScanHeader,
    /// `None` once a write failed: the failure was reported, the rest of the scan is not written.
    partial: Option<PartialScan>,
}

impl Recorder {
    /// Starts the recorder's thread; it ends when the sender is dropped and everything sent is written.
    pub fn spawn(self) -> mpsc::UnboundedSender<Record> {
        let (records, inbox) = mpsc::unbounded_channel();
        std::thread::Builder::new()
            .name(format!("recorder {}", self.job))
            .spawn(move || self.run(inbox))
            .expect("a thread starts");
        records
    }

    fn run(self, mut inbox: mpsc::UnboundedReceiver<Record>) {
        let mut open: HashMap<ProfileKey, Open> = HashMap::new();
        loop {
            // Points are written in batches: whatever came together goes out in one write once nothing more is
            // waiting (a scan's points come a line of several at a time).
            let record = match inbox.try_recv() {
                Ok(record) => record,
                Err(mpsc::error::TryRecvError::Empty) => {
                    self.flush(&mut open);
                    match inbox.blocking_recv() {
                        Some(record) => record,
                        None => break,
                    }
                }
                Err(mpsc::error::TryRecvError::Disconnected) => break,
            };
            match record {
                Record::Start { key, scan, header } => {
                    let partial = match self.dir.start_partial(&scan, &header) {
                        Ok(partial) => Some(partial),
                        Err(error) => {
                            self.failed(key, error.to_string());
                            None
                        }
                    };
                    open.insert(
                        key,
                        Open {
                            scan,
                            header,
                            partial,
                        },
                    );
                }
                Record::Point { key, raw } => {
                    let Some(scan) = open.get_mut(&key) else {
                        continue;
                    };
                    if let Some(Err(error)) = scan.partial.as_mut().map(|p| p.push(&raw)) {
                        scan.partial = None;
                        self.failed(key, error.to_string());
                    }
                }
                Record::End {
                    key,
                    points,
                    stats,
                    verdict,
                } => {
                    if let Some(mut scan) = open.remove(&key) {
                        if let Some(Err(error)) = scan.partial.as_mut().map(PartialScan::flush) {
                            scan.partial = None;
                            self.failed(key, error.to_string());
                        }
                        if scan.partial.is_some() {
                            self.complete(key, scan, points, stats, verdict);
                        }
                    }
                }
                Record::Cut { key } => {
                    if let Some(Some(mut partial)) = open.remove(&key).map(|scan| scan.partial) {
                        // The cut scan's points stay on disk for the record and the way out.
                        let _ = partial.flush();
                    }
                }
            }
        }
        self.flush(&mut open);
    }

    /// Hands every open scan's buffered points to the operating system.
    fn flush(&self, open: &mut HashMap<ProfileKey, Open>) {
        for (key, scan) in open.iter_mut() {
            if let Some(Err(error)) = scan.partial.as_mut().map(PartialScan::flush) {
                scan.partial = None;
                self.failed(*key, error.to_string());
            }
        }
    }

    fn complete(
        &self,
        key: ProfileKey,
        scan: Open,
        points: Vec<RawPoint>,
        stats: Option<DeviationStats>,
        verdict: Option<Verdict>,
    ) {
        let count = points.len();
        let file = ScanFile {
            header: scan.header,
            finished: clock::now_rfc3339(),
            points,
        };
        if let Err(error) = self.dir.write_scan(&scan.scan, &file) {
            self.failed(key, error.to_string());
            return;
        }
        let _ = self.events.send(Event::ProfileDone {
            job: self.job.clone(),
            machine: file.header.machine,
            scan: scan.scan,
            points: count,
            stats,
            verdict,
            at_unix_ms: clock::unix_ms(),
        });
        self.stored(key, Ok(()));
    }

    fn failed(&self, key: ProfileKey, error: String) {
        self.stored(key, Err(error));
    }

    fn stored(&self, key: ProfileKey, result: Result<(), String>) {
        let _ = self.daemon.blocking_send(DaemonMsg::Stored {
            job: self.job.clone(),
            key,
            result,
        });
    }
}
