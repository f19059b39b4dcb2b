//! DCP, the Discovery and basic Configuration Protocol (IEC 61158-6-10), device
//! side: `profidrive.md` §2.3–2.5, P-007…P-011.
//!
//! - [`pdu`]: the wire format, header and blocks, parse and emit.
//! - [`name`]: the name of station and its rules.
//! - [`signal`]: the identification flash of the SF LED (P-011).
//! - [`server`]: [`DcpServer`], which answers Identify, Get and Set.
//!
//! # Behaviour (for `docs/conformance.md`)
//!
//! - **Identify** (FrameID 0xFEFE, to 01:0e:cf:00:00:00 or our MAC): answered
//!   for All, or when every filter block matches: name of station, alias name,
//!   device vendor, device ID, device role, device instance, IP parameter. Any
//!   other filter, an empty filter or a malformed one: no answer. The answer
//!   (FrameID 0xFEFF, unicast to the requester) carries device vendor, name of
//!   station, device ID, role, options, (alias if it matched by alias),
//!   instance and IP parameter, and is to be sent `10 ms × (h mod factor)`
//!   after the request, h = XOR of the MAC's three 16-bit words (factor 0/1: at
//!   once; factors over 0x1900 are clamped).
//! - **Get** (0xFEFD, unicast): one block per requested pair; what cannot be
//!   read answers a Control/Response block: option not supported (0x01) for
//!   options the device lacks (DHCP, manufacturer options), suboption not
//!   supported (0x02) for unknown suboptions, the Control option and an alias
//!   not (yet) learned. All (0xFF,0xFF) returns every readable block.
//! - **Set** (0xFEFD, unicast): each block is applied in order and answered
//!   by a Control/Response block. Name of station (2,2) and IP parameter (1,2)
//!   with BlockQualifier bit 0 = permanent; an invalid name or IP suite, or a
//!   value of the wrong length: suboption not set (0x03); while
//!   [`DcpServer::set_in_operation`] a change of name or IP and any reset:
//!   in operation (0x06). Full IP suite, MAC and the other device properties
//!   cannot be set (0x02); DHCP is not supported (0x01). Start/Stop
//!   transaction are acknowledged (each frame is applied as it comes). Signal
//!   (qualifier 0, value 0x0100) starts the flash. Reset to factory: mode 1
//!   (application data) only raises the event, modes 2 (communication), 4 and
//!   8 (all data) and the older Factory reset (5,5) also clear name and IP;
//!   other modes: 0x02.
//! - A request whose header or blocks are truncated or run past
//!   DCPDataLength is dropped and changes nothing; an unknown ServiceID on
//!   0xFEFD answers ServiceType 0x05 "not supported"; responses, Hellos of
//!   other devices and multicast Get/Set are ignored.
//! - After a Get/Set from one controller, Get/Set from other MACs are ignored
//!   for 3 s ([`server::SAM_HOLD`]).
//! - The server persists nothing: every change is an [`Event`]; a temporary
//!   Set tells the store to clear the stored value (a DCP assignment replaces
//!   a stored static IP, P-009).
//! - Answers are untagged, from the interface MAC, padded to 60 bytes.

pub mod name;
pub mod pdu;
pub mod server;
pub mod signal;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_frames;
#[cfg(test)]
mod tests_pdu;

pub use name::{NameError, NameOfStation};
pub use pdu::{BlockError, BlockType, IpSuite};
pub use server::{DcpServer, Event, Events, Identity, Outcome, Reply, ResetMode};
pub use signal::Signal;
