//! Simulated EtherCAT slave controller (register level) and, later, motor and load.
//!
//! The simulated ESC ([`esc`]) processes real EtherCAT frames ([`frame`]); the
//! slave stack reaches it only through [`esc::Pdi`](::esc::Pdi), exactly as on
//! hardware. The ESC core is `no_std` and heap-free; the `std` feature adds the
//! line of drives in simulated time ([`sim`]), the in-process master link
//! ([`master`]), raw Ethernet ([`raw`]) and pcap recording ([`pcap`]).
#![cfg_attr(not(feature = "std"), no_std)]

pub mod electrical;
pub mod esc;
pub mod frame;
pub mod motor;
pub mod script;
pub mod world;

#[cfg(feature = "std")]
pub mod eoe;
#[cfg(feature = "std")]
pub mod fb;
#[cfg(feature = "std")]
pub mod master;
#[cfg(feature = "std")]
pub mod matrix;
#[cfg(feature = "std")]
pub mod pcap;
#[cfg(feature = "std")]
pub mod plants;
#[cfg(feature = "std")]
pub mod plot;
#[cfg(feature = "std")]
pub mod pn;
#[cfg(feature = "std")]
pub mod raw;
#[cfg(feature = "std")]
pub mod scope_plot;
#[cfg(feature = "std")]
pub mod sim;
