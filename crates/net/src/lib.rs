//! IP over the drive's EoE interface (spec §9, §10, §17): a smoltcp
//! interface on the EoE frame queue ([`ecat::eoe_queue::EoeQueue`]) that
//! answers ping, takes its address from the master's set-IP-parameter
//! service (E-096), serves parameters over UDP by coordinate through the
//! object dictionary ([`param`]) and keeps an SNTP-disciplined clock
//! ([`sntp`], E-102..E-106).
//!
//! `no_std`, heap-free: the sockets' buffers are borrowed ([`NetBuffers`],
//! [`SocketSlots`]); time is always an argument (local µs since power-on);
//! randomness comes from a seed. The drive itself does not depend on this
//! crate: it owns the queue and lends it with its dictionary through
//! `drive_ecat::runtime::Drive::with_eoe`.
#![no_std]

pub mod device;
pub mod param;
pub mod real;
pub mod sntp;
pub mod stack;
#[cfg(feature = "testing")]
pub mod testing;

pub use device::QueueDevice;
/// smoltcp, as this crate uses it (for the owner's `SocketStorage::EMPTY`).
pub use smoltcp;
pub use stack::{
    NetBuffers, NetConfig, NetSettings, NetStack, NetStats, SocketSlots, PARAM_BURST, PARAM_REFILL, SOCKETS,
};
