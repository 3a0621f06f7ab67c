//! The contact history: one [`ContactRecord`] per listed contact (every
//! sub-model's declared values, [`HISTORY_WIDTH`] of them) and its sliding
//! flag, as two parallel columns. The neighbour rebuild carries a contact's
//! whole record over by the pair's key, whatever the width, and the kernels
//! split the columns into the stripes' runs.
use serde::{Deserialize, Serialize};

use super::{ContactRecord, HISTORY_WIDTH, TANGENTIAL_HISTORY};

/// The history of a list of contacts (particle pairs or wall pairs), in list order.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct ContactHistory {
    /// Each contact's record: all zero while it has not touched.
    pub records: Vec<ContactRecord>,
    /// Whether the contact slid (its shear spring at the Coulomb cap) in its
    /// last evaluation.
    pub sliding: Vec<bool>,
}

/// A contiguous run of a [`ContactHistory`], to update in place.
pub struct HistoryRun<'a> {
    /// The run's records.
    pub records: &'a mut [ContactRecord],
    /// The run's sliding flags.
    pub sliding: &'a mut [bool],
}

impl HistoryRun<'_> {
    /// Number of contacts in the run.
    pub fn len(&self) -> usize {
        self.records.len().min(self.sliding.len())
    }

    /// True when the run holds no contact.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl ContactHistory {
    /// Number of contacts.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    /// True when there is no contact.
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// Appends a contact that has not touched.
    pub fn push_untouched(&mut self) {
        self.records.push([0.0; HISTORY_WIDTH]);
        self.sliding.push(false);
    }

    /// Appends contact `k` of `other`, its record and flag as they are.
    pub fn push_from(&mut self, other: &ContactHistory, k: usize) {
        self.records.push(other.records[k]);
        self.sliding.push(other.sliding[k]);
    }

    /// Whether contact `k` carries any history (a value other than 0, or the
    /// sliding flag): the contacts the rebuild carries over.
    pub fn touched(&self, k: usize) -> bool {
        self.records[k].iter().any(|&v| v != 0.0) || self.sliding[k]
    }

    /// Contact `k`'s tangential sub-model value: the shear spring (N) of a
    /// linear contact, the tangential displacement (m) of a Hertz-Mindlin one.
    pub fn shear_spring(&self, k: usize) -> f64 {
        self.records[k][TANGENTIAL_HISTORY.start]
    }

    /// Every contact's shear spring, in list order (N).
    pub fn shear_springs(&self) -> Vec<f64> {
        (0..self.len()).map(|k| self.shear_spring(k)).collect()
    }

    /// The whole history as one run.
    pub fn run(&mut self) -> HistoryRun<'_> {
        HistoryRun {
            records: &mut self.records,
            sliding: &mut self.sliding,
        }
    }

    /// Contacts `lo..hi` as one run.
    pub fn run_of(&mut self, lo: usize, hi: usize) -> HistoryRun<'_> {
        HistoryRun {
            records: &mut self.records[lo..hi],
            sliding: &mut self.sliding[lo..hi],
        }
    }

    /// The history split at the contiguous `ranges` (which tile it in order).
    pub fn split(&mut self, ranges: &[(usize, usize)]) -> Vec<HistoryRun<'_>> {
        let records = crate::parallel::split_ranges(&mut self.records, ranges);
        let sliding = crate::parallel::split_ranges(&mut self.sliding, ranges);
        records
            .into_iter()
            .zip(sliding)
            .map(|(records, sliding)| HistoryRun { records, sliding })
            .collect()
    }
}

/// A contact that is not touching: its history is cleared (written only when
/// set, so that a record of -0 values stays as it is).
#[inline(always)]
pub fn forget(record: &mut ContactRecord, sliding: &mut bool) {
    if record.iter().any(|&v| v != 0.0) || *sliding {
        *record = [0.0; HISTORY_WIDTH];
        *sliding = false;
    }
}
