//! What goes into and comes out of a model drive besides the process images (manual 3.2.2,
//! 3.9, 4.9): acyclic records, connection events and trace events.

use crate::{DecodeError, ErrorCode};
use drivespec_positioner::{CoreEvent, Micros};
use serde::{Deserialize, Serialize};

/// A change of the connection to the IO controller (manual 3.9, 4.9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinkEvent {
    /// The controller connects (again); images are processed from now on (3.9).
    Connected,
    /// The connection is interrupted: the outputs become 0 (3.9 item 2) and a run aborts (4.9).
    Lost,
    /// IOPS = bad (controller CPU in STOP): the outputs keep their last valid value (3.9 item 1).
    IopsBad,
    /// IOPS = good again (3.9).
    IopsGood,
}

/// An acyclic request (manual 3.2.2).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
#[serde(tag = "op", rename_all = "kebab-case")]
pub enum RecordRequest {
    /// Read record: index = parameter number (3.2.2).
    Read {
        /// Record index.
        index: u16,
    },
    /// Write record: control byte and value (3.2.2).
    Write {
        /// Record index.
        index: u16,
        /// Data as on the wire (control byte first).
        data: Vec<u8>,
    },
}

/// A successful answer to a record request (manual 3.2.2).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum RecordAnswer {
    /// The data of a read: 2 or 4 bytes, or the whole string (3.3 par. 13).
    Data {
        /// Bytes as on the wire.
        bytes: Vec<u8>,
    },
    /// The write was executed (3.2.2).
    Written,
    /// The write was ignored: control byte 0 (PSD-REC-004).
    Ignored,
}

/// Why a record request failed (manual 3.2.2; DECISION: refusals carry the PKW error table's
/// codes, the manual gives no record error codes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum RecordFailure {
    /// The data does not have the length the parameter needs (3.2.2 notices).
    Malformed {
        /// What is wrong.
        #[serde(skip)]
        error: DecodeError,
    },
    /// The drive refuses the request, with the PKW error code that would apply (3.8).
    Refused {
        /// Error code.
        error: ErrorCode,
    },
}

/// The answer to one record request (manual 3.2.2).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct RecordResponse {
    /// When it was answered (3.2.2).
    pub at: Micros,
    /// Record index of the request (3.2.2).
    pub index: u16,
    /// The answer (3.2.2).
    pub result: Result<RecordAnswer, RecordFailure>,
}

/// Something the model did, for traces (manual chapter 4, 3.3 par. 96).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
#[serde(tag = "event", rename_all = "kebab-case")]
pub enum Event {
    /// The positioning core's events (runs, refusals, power) (chapter 4).
    Core(CoreEvent),
    /// A parameter was written through PKW or a record (3.2.2).
    ParameterWritten {
        /// Parameter number.
        pnu: u16,
        /// Value written.
        value: i64,
    },
    /// The parameters were saved to EEPROM (par. 96 = 1, -5, -3).
    Saved,
    /// The working parameters were loaded from the delivery table or the EEPROM image (chapter 4).
    Restored {
        /// From the delivery table (true) or the user's saved image.
        delivery: bool,
    },
    /// The station name was deleted (par. 96 = -3).
    StationNameCleared,
    /// The connection changed (3.9).
    Link(LinkEvent),
}
