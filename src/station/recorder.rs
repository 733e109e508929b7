//! A job's recorder: the one thread that writes its scans to disk. Every point goes to its profile's partial file
//! as it comes (a killed daemon keeps it); a finished profile's scan file is written and flushed, and only then is
//! the profile announced done and counted. Opening files and flushing them to the disk take milliseconds, which
//! the live deviations must not wait for, so none of it happens on the analysis task.
//!
//! The queue to the recorder is bounded ([`RECORDER_QUEUE`]): a disk that stalls for longer than it holds makes
//! the analysis wait at its send, the analysis' own bounded queue then makes the machine workers wait, and no
//! queue grows without end.

use std::collections::HashMap;
use std::io;

use tokio::sync::{broadcast, mpsc};

use super::clock;
use super::core::Input;
use super::journal::{JobDir, PartialScan, ScanFile, ScanHeader};
use super::DaemonMsg;
use crate::analysis::stats::{DeviationStats, Verdict};
use crate::analysis::RawPoint;
use crate::api::{Event, ScanRef};
use crate::plan::ProfileKey;

/// Records waiting for the recorder: some 10 s of points from five machines scanning 20 points a second, far
/// longer than a healthy disk ever keeps it waiting (a file is opened or flushed in milliseconds). A record
/// takes 152 bytes in the queue (a scan's points at its end are on the heap, one scan per profile), so the queue
/// holds about 160 kB.
pub(crate) const RECORDER_QUEUE: usize = 1024;

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

/// Where the recorder writes: the job's folder, or in tests a disk that stalls.
pub(crate) trait Disk: Send + 'static {
    type Partial: Partial;
    fn start_partial(&self, scan: &ScanRef, header: &ScanHeader) -> io::Result<Self::Partial>;
    fn write_scan(&self, scan: &ScanRef, file: &ScanFile) -> io::Result<()>;
}

/// The partial file of the profile being scanned.
pub(crate) trait Partial: Send {
    fn push(&mut self, point: &RawPoint) -> io::Result<()>;
    fn flush(&mut self) -> io::Result<()>;
}

impl Disk for JobDir {
    type Partial = PartialScan;

    fn start_partial(&self, scan: &ScanRef, header: &ScanHeader) -> io::Result<PartialScan> {
        JobDir::start_partial(self, scan, header)
    }

    fn write_scan(&self, scan: &ScanRef, file: &ScanFile) -> io::Result<()> {
        JobDir::write_scan(self, scan, file)
    }
}

impl Partial for PartialScan {
    fn push(&mut self, point: &RawPoint) -> io::Result<()> {
        PartialScan::push(self, point)
    }

    fn flush(&mut self) -> io::Result<()> {
        PartialScan::flush(self)
    }
}

/// Where the recorder reports.
pub struct Recorder<D = JobDir> {
    pub job: String,
    pub dir: D,
    pub events: broadcast::Sender<Event>,
    pub daemon: mpsc::Sender<DaemonMsg>,
}

struct Open<P> {
    scan: ScanRef,
    header: ScanHeader,
    /// `None` once a write failed: the failure was reported, the rest of the scan is not written.
    partial: Option<P>,
}

impl<D: Disk> Recorder<D> {
    /// Starts the recorder's thread; it ends when the sender is dropped and everything sent is written, which
    /// its handle tells.
    pub fn spawn(self) -> (mpsc::Sender<Record>, std::thread::JoinHandle<()>) {
        let (records, inbox) = mpsc::channel(RECORDER_QUEUE);
        let thread = std::thread::Builder::new()
            .name(format!("recorder {}", self.job))
            .spawn(move || self.run(inbox))
            .expect("a thread starts");
        (records, thread)
    }

    fn run(self, mut inbox: mpsc::Receiver<Record>) {
        let mut open: HashMap<ProfileKey, Open<D::Partial>> = HashMap::new();
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
                        if let Some(Err(error)) = scan.partial.as_mut().map(Partial::flush) {
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
    fn flush(&self, open: &mut HashMap<ProfileKey, Open<D::Partial>>) {
        for (key, scan) in open.iter_mut() {
            if let Some(Err(error)) = scan.partial.as_mut().map(Partial::flush) {
                scan.partial = None;
                self.failed(*key, error.to_string());
            }
        }
    }

    fn complete(
        &self,
        key: ProfileKey,
        scan: Open<D::Partial>,
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
        let _ = self.daemon.blocking_send(DaemonMsg::Input(Input::Stored {
            job: self.job.clone(),
            key,
            result,
        }));
    }
}
