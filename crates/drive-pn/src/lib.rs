//! The drive on PROFINET: [`PnDrive`] puts the PROFINET IO device
//! ([`profinet::device::Device`]) in front of the fieldbus-neutral drive core
//! ([`drive_core`]: the object dictionary and both axes), the way `drive`
//! puts the EtherCAT slave stack in front of it.
//!
//! What the personality translates:
//!
//! | core | PROFINET |
//! |---|---|
//! | a fault raised (T13): E82 event HH, E43 cause S | a diagnosis alarm "appears", ChannelErrorType 0x1000 + HH, ExtChannelErrorType 0x1000 + S (P-030…P-033, Q-13) |
//! | the fault reset (T15) | "disappears" (P-035) |
//! | event 52 cause 6 (communication: process data lost), both axes, fault reaction | the AR lost: the output CR's watchdog expired or the alarm channel failed (P-036, Q-07) |
//! | a new set-point each control cycle | a valid output frame since the last cycle |
//!
//! The telegram mapping of the profile (CW1/ZSW1, PNU) is the next layer
//! (issue 17); until then the cyclic data is reachable as bytes
//! ([`PnDrive::device`]). `#![no_std]`, heap-free, time as an argument.
#![no_std]
#![deny(missing_docs)]

use drive_core::axis::{Axis, AxisCache, AxisCommand, AxisIo};
use drive_core::faults::{FaultChange, E82_INACTIVE};
use drive_core::params::{E43, E82};
use drive_core::DriveObjects;
use nanos::Nanos;
use profinet::cm::{NoRecords, RecordHook};
use profinet::device::{Device, DeviceConfig, DeviceEvent, RtEvent};

#[cfg(test)]
extern crate std;
#[cfg(test)]
mod tests;

/// The event a lost AR raises on both axes: event 52 (communication).
pub const AR_LOST_EVENT: u8 = 52;
/// Its cause: 6, process data lost (the cause EtherCAT's PDO timeout uses).
pub const AR_LOST_CAUSE: u8 = 6;

/// The drive on PROFINET. See the [crate documentation](crate).
pub struct PnDrive<H: RecordHook = NoRecords> {
    device: Device<H>,
    objects: DriveObjects,
    axes: [Axis; 2],
    caches: [AxisCache; 2],
    /// The diagnosis (HH, S) each axis' fault raised, to clear it on T15.
    raised: [Option<(u8, u8)>; 2],
    /// A valid output frame arrived since the last control cycle.
    exchanged: bool,
}

impl PnDrive<NoRecords> {
    /// A drive with the device settings `config` and default parameters.
    pub fn new(config: DeviceConfig) -> PnDrive<NoRecords> {
        PnDrive::with_hook(config, NoRecords)
    }
}

impl<H: RecordHook> PnDrive<H> {
    /// A drive whose device serves the profile's records through `hook`.
    pub fn with_hook(config: DeviceConfig, hook: H) -> PnDrive<H> {
        PnDrive {
            device: Device::new(config, hook),
            objects: DriveObjects::new(),
            axes: [Axis::new(0), Axis::new(1)],
            caches: [AxisCache::new(), AxisCache::new()],
            raised: [None; 2],
            exchanged: false,
        }
    }

    /// The PROFINET device.
    pub fn device(&self) -> &Device<H> {
        &self.device
    }

    /// The PROFINET device, mutable (input data, link state).
    pub fn device_mut(&mut self) -> &mut Device<H> {
        &mut self.device
    }

    /// The object dictionary.
    pub fn objects(&self) -> &DriveObjects {
        &self.objects
    }

    /// The object dictionary, mutable.
    pub fn objects_mut(&mut self) -> &mut DriveObjects {
        &mut self.objects
    }

    /// The axes.
    pub fn axes(&self) -> &[Axis; 2] {
        &self.axes
    }

    /// The axes, mutable.
    pub fn axes_mut(&mut self) -> &mut [Axis; 2] {
        &mut self.axes
    }

    /// A received Ethernet frame at `now`; answers go out through `tx`.
    /// Returns the device's events the application acts on (name/IP to
    /// persist, DCP signal, AR changes), one at a time through `on_event`.
    pub fn receive(
        &mut self,
        now: Nanos,
        frame: &[u8],
        tx: &mut impl FnMut(&[u8]),
        on_event: &mut impl FnMut(&DeviceEvent),
    ) {
        self.device.receive(now, frame, tx);
        self.events(on_event);
    }

    /// The device's timers at `now`; returns when to call again at the latest.
    pub fn poll(
        &mut self,
        now: Nanos,
        tx: &mut impl FnMut(&[u8]),
        on_event: &mut impl FnMut(&DeviceEvent),
    ) -> Nanos {
        let next = self.device.poll(now, tx);
        self.events(on_event);
        next
    }

    fn events(&mut self, on_event: &mut impl FnMut(&DeviceEvent)) {
        if self.device.exchanging() {
            self.exchanged = true;
        }
        while let Some(e) = self.device.take_event() {
            if let DeviceEvent::Rt(RtEvent::ArLost(_)) = e {
                self.raise_ar_lost();
            }
            on_event(&e);
        }
    }

    /// the AR is gone; both axes run their fault reaction.
    fn raise_ar_lost(&mut self) {
        let event = motion::Event {
            number: u16::from(AR_LOST_EVENT),
            cause: AR_LOST_CAUSE,
        };
        for axis in self.axes.iter_mut() {
            axis.raise_event(event);
        }
    }

    /// One control cycle of both axes at `now` with the hardware inputs `io`;
    /// returns the power-stage commands. A fault raised or reset becomes a
    /// diagnosis alarm appearing or disappearing, and E82/E43 follow it.
    pub fn control_cycle(&mut self, now: Nanos, io: &[AxisIo; 2]) -> [AxisCommand; 2] {
        let new = core::mem::take(&mut self.exchanged) || !self.device.exchanging();
        let mut commands = [AxisCommand::OFF; 2];
        for (i, ((axis, cache), io)) in self
            .axes
            .iter_mut()
            .zip(self.caches.iter_mut())
            .zip(io)
            .enumerate()
        {
            let report = axis.cycle_cached(cache, &mut self.objects, io, now, new);
            let (Some(command), Some(raised)) = (commands.get_mut(i), self.raised.get(i).copied()) else {
                continue;
            };
            match report.fault {
                Some(FaultChange::Raised(f)) => {
                    let _ = self.objects.set(E82, 0, i64::from(f.event));
                    let _ = self.objects.set(E43, 0, i64::from(f.cause));
                    if self.device.raise_diagnosis(f.event, f.cause) {
                        if let Some(r) = self.raised.get_mut(i) {
                            *r = Some((f.event, f.cause));
                        }
                    }
                }
                Some(FaultChange::Cleared) => {
                    let _ = self.objects.set(E82, 0, i64::from(E82_INACTIVE));
                    let _ = self.objects.set(E43, 0, 0);
                    if let Some(r) = self.raised.get_mut(i) {
                        *r = None;
                    }
                    // the diagnosis sits on the drive (DAP subslot 1): it goes
                    // when no axis holds it any more
                    if let Some((hh, s)) = raised {
                        if !self.raised.contains(&Some((hh, s))) {
                            self.device.clear_diagnosis(hh, s);
                        }
                    }
                }
                None => {}
            }
            *command = report.command;
        }
        commands
    }
}
