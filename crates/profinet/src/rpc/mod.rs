//! DCE/RPC connectionless (CL) over UDP port 34964, as PROFINET IO uses it.
//!
//! - [`header`]: the 80-byte CL header ([`Header::parse`] / [`Header::emit`]),
//!   packet types, flags, `drep` (big- and little-endian both handled).
//! - [`uuid`]: [`Uuid`] and the PNIO/EPM interface UUIDs.
//! - [`epm`]: the endpoint mapper lookup controllers send first.
//! - [`server`]: the engine — request reassembly into a bounded buffer,
//!   response fragmentation (the request's fragment size, else 1464-byte PDUs),
//!   duplicate requests, ping/working/nocall, ack, fack, reject for unknown
//!   interfaces/opnums/boot times, and the device's own client call (CControl).
//!
//! The PNIO device interface's calls go to a [`Handler`] (the CM,
//! [`crate::cm`]); the RPC layer knows nothing of their NDR bodies.

pub mod cursor;
pub mod epm;
pub mod header;
pub mod server;
#[cfg(test)]
pub(crate) mod tests;
pub mod uuid;

pub use cursor::Endian;
pub use header::{flags1, Drep, Header, HeaderError, PacketType, HEADER_LEN, MUST_RECV_FRAG_SIZE};
pub use server::{RpcCounters, Server, ServerConfig};
pub use uuid::Uuid;

use crate::ip::Endpoint;
use nanos::Nanos;

/// PNIO operation numbers of the device interface.
pub mod opnum {
    /// Connect (establish an AR).
    pub const CONNECT: u16 = 0;
    /// Release (end an AR).
    pub const RELEASE: u16 = 1;
    /// Read a record.
    pub const READ: u16 = 2;
    /// Write a record.
    pub const WRITE: u16 = 3;
    /// Control (PrmEnd; ApplicationReady towards the controller).
    pub const CONTROL: u16 = 4;
    /// Read a record without an AR.
    pub const READ_IMPLICIT: u16 = 5;
}

/// Highest opnum of the PNIO device interface.
pub const MAX_PNIO_OPNUM: u16 = opnum::READ_IMPLICIT;

/// NCA status codes of reject and fault PDUs.
pub mod nca {
    /// The opnum does not exist on the interface.
    pub const OP_RNG_ERROR: u32 = 0x1C01_0002;
    /// Unknown interface (or version).
    pub const UNK_IF: u32 = 0x1C01_0003;
    /// The client's idea of our boot time is stale.
    pub const WRONG_BOOT_TIME: u32 = 0x1C01_0006;
    /// Protocol error (e.g. an undecodable body).
    pub const PROTO_ERROR: u32 = 0x1C01_000B;
    /// The output arguments are too big.
    pub const OUT_ARGS_TOO_BIG: u32 = 0x1C01_0013;
    /// The server is too busy.
    pub const SERVER_TOO_BUSY: u32 = 0x1C01_0014;
    /// The request is too big for our buffer.
    pub const FAULT_REMOTE_NO_MEMORY: u32 = 0x1C00_001B;
}

/// One call handed to the [`Handler`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Call {
    /// The client.
    pub peer: Endpoint,
    /// Operation number ([`opnum`]).
    pub opnum: u16,
    /// Byte order of the NDR body (and of the response's).
    pub endian: Endian,
    /// Object UUID of the request.
    pub object: Uuid,
    /// Activity UUID of the request.
    pub activity: Uuid,
    /// Sequence number of the request.
    pub seq: u32,
    /// The request was longer than the reassembly buffer and the body handed
    /// over is its beginning only (a PNIO Write: the handler answers the
    /// record's header with "write length error").
    pub truncated: bool,
}

/// A call refused by the handler at the RPC level (PNIO errors travel in a
/// normal response's PNIO status instead).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CallError {
    /// Answer with a reject PDU carrying this [`nca`] status.
    Reject(u32),
    /// Answer with a fault PDU carrying this [`nca`] status.
    Fault(u32),
}

/// A call the device makes (written by [`Handler::request`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Request {
    /// The controller's RPC endpoint.
    pub peer: Endpoint,
    /// Object UUID (the controller's CMInitiatorObjectUUID).
    pub object: Uuid,
    /// Interface UUID ([`uuid::PNIO_CONTROLLER_INTERFACE`]).
    pub interface: Uuid,
    /// Operation number.
    pub opnum: u16,
    /// Bytes of the body written into the handler's buffer.
    pub body_len: usize,
}

/// How a call of the device ended without a response body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClientError {
    /// No answer after [`server::CLIENT_ATTEMPTS`] transmissions.
    Timeout,
    /// Rejected with this status.
    Reject(u32),
    /// Faulted with this status.
    Fault(u32),
    /// A fragmented response (not expected for CControl; refused).
    Fragmented,
}

/// What the RPC engine calls for the PNIO device interface.
pub trait Handler {
    /// Executes a call: `body` is the reassembled NDR body in `call.endian`;
    /// the response body goes into `out`, its length is returned.
    fn call(&mut self, now: Nanos, call: &Call, body: &[u8], out: &mut [u8]) -> Result<usize, CallError>;

    /// Offers a call for the device to make, its body written into `body`
    /// in [`Server::CLIENT_ENDIAN`] order. Asked by [`Server::poll`] whenever
    /// no client call is outstanding.
    fn request(&mut self, _now: Nanos, _body: &mut [u8]) -> Option<Request> {
        None
    }

    /// The end of the device's call: the response body (with its byte order)
    /// or why there is none.
    fn response(&mut self, _now: Nanos, _result: Result<(Endian, &[u8]), ClientError>) {}
}
