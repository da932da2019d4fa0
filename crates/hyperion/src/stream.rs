//! The peak stream's backlog: every scan the instrument made recently, so a reader that keeps up
//! receives each one (its serial numbers consecutive), and a streaming divider that sends every
//! n-th scan.
//!
//! The instrument scans at its laser scan speed and numbers each scan; with divider n it streams
//! the scans whose serial number is a multiple of n (so streamed serial numbers step by n). A reader
//! that falls more than [`BACKLOG_SCANS`] behind loses the oldest scans, which the serial numbers
//! show as a gap, as on the instrument when its stream buffer overflows.

use super::peaks::PeakFrame;
use std::collections::VecDeque;

/// Scans kept for slow readers: 1 s at the si255's 1 kHz.
pub const BACKLOG_SCANS: usize = 1000;

/// The most recent scans, oldest first.
#[derive(Debug, Clone, Default)]
pub struct ScanBacklog {
    scans: VecDeque<PeakFrame>,
}

impl ScanBacklog {
    /// An empty backlog.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends a scan, dropping the oldest beyond [`BACKLOG_SCANS`].
    pub fn push(&mut self, scan: PeakFrame) {
        if self.scans.len() == BACKLOG_SCANS {
            self.scans.pop_front();
        }
        self.scans.push_back(scan);
    }

    /// Serial number of the newest scan.
    pub fn latest_serial(&self) -> Option<u64> {
        self.scans.back().map(|s| s.header.serial_number)
    }

    /// The scans to stream after the one numbered `sent` (all kept ones when `None`), with
    /// divider `divider` (0 is taken as 1): those whose serial number is a multiple of it.
    pub fn to_stream(&self, sent: Option<u64>, divider: u32) -> impl Iterator<Item = &PeakFrame> {
        let divider = u64::from(divider.max(1));
        // Serial numbers ascend: skip the ones sent by bisection, not one by one (this runs for
        // every stream connection on every tick, under the devices' lock).
        let first = sent.map_or(0, |sent| self.scans.partition_point(|s| s.header.serial_number <= sent));
        self.scans.range(first..).filter(move |s| s.header.serial_number.is_multiple_of(divider))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PeakHeader;

    fn scan(serial: u64) -> PeakFrame {
        PeakFrame { header: PeakHeader { serial_number: serial, ..PeakHeader::default() }, channels: vec![] }
    }

    fn serials<'a>(it: impl Iterator<Item = &'a PeakFrame>) -> Vec<u64> {
        it.map(|s| s.header.serial_number).collect()
    }

    #[test]
    fn a_reader_gets_every_scan_after_the_last_it_got() {
        let mut backlog = ScanBacklog::new();
        (1..=5).for_each(|k| backlog.push(scan(k)));
        assert_eq!(serials(backlog.to_stream(Some(2), 1)), [3, 4, 5]);
        assert_eq!(serials(backlog.to_stream(Some(5), 1)), Vec::<u64>::new());
        assert_eq!(backlog.latest_serial(), Some(5));
    }

    #[test]
    fn the_divider_streams_every_nth_scan() {
        let mut backlog = ScanBacklog::new();
        (1..=35).for_each(|k| backlog.push(scan(k)));
        assert_eq!(serials(backlog.to_stream(Some(0), 10)), [10, 20, 30]);
        assert_eq!(serials(backlog.to_stream(Some(20), 10)), [30]);
        assert_eq!(serials(backlog.to_stream(Some(33), 0)), [34, 35], "0 acts as 1");
    }

    #[test]
    fn the_backlog_is_bounded() {
        let mut backlog = ScanBacklog::new();
        (1..=BACKLOG_SCANS as u64 + 10).for_each(|k| backlog.push(scan(k)));
        let kept = serials(backlog.to_stream(None, 1));
        assert_eq!(kept.len(), BACKLOG_SCANS);
        assert_eq!(kept[0], 11);
    }
}
