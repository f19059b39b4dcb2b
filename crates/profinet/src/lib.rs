//! PROFINET IO device (conformance class B, RT_CLASS_1), sans-IO: frames in,
//! frames out, time as an argument ([`nanos::Nanos`]). `shared/spec/profidrive.md`
//! §2 and items P-001…P-043 of `features-profidrive.md`.
//!
//! - [`wire`]: Ethernet II / 802.1Q views, EtherType and FrameID dispatch.
//! - [`dcp`]: Discovery and basic Configuration (Identify, Get, Set, Signal,
//!   Reset to factory, Hello), the station's name and IP.
//! - [`lldp`]: LLDP transmit with the PROFINET TLVs.
//! - [`ip`]: ARP, IPv4, ICMP echo and UDP for the RPC server.
//! - [`rpc`]: DCE/RPC connectionless (header, fragments, endpoint mapper).
//! - [`cm`]: context management blocks (Connect, Read/Write, Control) and the AR.
//! - [`rt`]: RT_CLASS_1 cyclic consumer/provider, watchdog and data hold.
//! - [`alarm`]: the acyclic real-time alarm channel (RTA), diagnosis alarms.
//! - [`pdev`]: the physical device records (PDPortDataReal/Adjust,
//!   PDInterfaceDataReal) of the interface and its ports.
//! - [`profienergy`]: the PROFIenergy service protocol of record 0x80A0.
//! - [`device`]: all of them behind one frame input and one timer ([`device::Device`]).
//! - [`model`]: the device's module model (DAP, IN/OUT modules) and identity, the
//!   one declaration the firmware and the GSDML share.
//!
//! `#![no_std]`, heap-free and panic-free on every path frame bytes reach: every
//! view is checked once (`new_checked`) and no accessor panics afterwards.
#![no_std]
// unwrap/expect/panic!/indexing are denied by the workspace lints
// (Cargo.toml `[workspace.lints.clippy]`; tests may use them, clippy.toml).
#![deny(missing_docs)]

pub mod alarm;
pub mod cm;
pub mod dcp;
pub mod device;
pub mod ip;
pub mod led;
pub mod lldp;
pub mod model;
pub mod pdev;
pub mod profienergy;
pub mod rpc;
pub mod rt;
pub mod wire;

pub use nanos::Nanos;

#[cfg(test)]
extern crate std;
#[cfg(any(test, feature = "testing"))]
pub mod testing;
#[cfg(test)]
pub(crate) mod tests_tshark;
