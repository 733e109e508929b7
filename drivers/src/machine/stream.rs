//! Results that arrive over time: scan points while a scan runs, positions while the machine moves.

use std::pin::Pin;
use std::task::{Context, Poll};

use futures::stream::{BoxStream, Stream};

use super::{Error, ScanPoint, Xyz};
use crate::wire::EventTag;

/// The points of one scan, in the order measured. Ends after the machine reports the scan complete;
/// an `Err` item is the last one and says why the scan stopped early.
pub struct ScanStream(BoxStream<'static, Result<ScanPoint, Error>>);

/// The positions a move-report daemon sends. Ends when the daemon is stopped; an `Err` item is last.
pub struct MoveReports {
    daemon: EventTag,
    positions: BoxStream<'static, Result<Xyz, Error>>,
}

impl ScanStream {
    /// A scan stream over `points` (drivers build these; tests can build one from canned points).
    pub fn new(points: impl Stream<Item = Result<ScanPoint, Error>> + Send + 'static) -> Self {
        ScanStream(Box::pin(points))
    }
}

impl MoveReports {
    /// The reports of the daemon with tag `daemon`.
    pub fn new(
        daemon: EventTag,
        positions: impl Stream<Item = Result<Xyz, Error>> + Send + 'static,
    ) -> Self {
        MoveReports {
            daemon,
            positions: Box::pin(positions),
        }
    }

    /// The daemon's tag, to stop it with.
    pub fn daemon(&self) -> EventTag {
        self.daemon
    }
}

impl Stream for ScanStream {
    type Item = Result<ScanPoint, Error>;

    fn poll_next(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Option<Self::Item>> {
        self.0.as_mut().poll_next(cx)
    }
}

impl Stream for MoveReports {
    type Item = Result<Xyz, Error>;

    fn poll_next(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Option<Self::Item>> {
        self.positions.as_mut().poll_next(cx)
    }
}
