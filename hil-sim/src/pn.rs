//! A simulated drive on PROFINET: the firmware's PROFINET IO device
//! ([`profinet::device::Device`]) with the settings a fresh drive ships with,
//! and the drive's side of the cyclic data as a loop-back (what the
//! controller writes into the drive's IN module comes back in its OUT
//! module), so a controller can check round trips. `hil-sim serve
//! --fieldbus profinet` runs it on a raw interface (`cli/serve_pn.rs`).

use nanos::Nanos;
use profinet::cm::{CmEvent, Im0, ImData};
use profinet::dcp::server::Event as DcpEvent;
use profinet::dcp::{IpSuite, NameOfStation};
use profinet::device::{Device, DeviceConfig, DeviceEvent, RtEvent, MAX_MODULE_BYTES};
use profinet::model;
use profinet::rpc::uuid::Uuid;
use profinet::wire::MacAddr;

/// The serial number in the simulated drive's I&M0.
pub const SERIAL_NUMBER: &str = "SIM0001";

/// The port MACs for an interface MAC (LLDP sources): locally administered
/// variants of it (bit 1 of the first byte set, the last byte + port number),
/// never the interface MAC itself.
pub fn port_macs(mac: MacAddr) -> [MacAddr; model::PORTS as usize] {
    let mut out = [mac; model::PORTS as usize];
    for (port, m) in (1u8..).zip(out.iter_mut()) {
        m.0[0] |= 0x02;
        m.0[5] = mac.0[5].wrapping_add(port);
    }
    out
}

/// The settings of a drive as shipped (no IP, the given name: empty for
/// none) on interface `mac`, started at `boot_time` (any value that differs
/// after every start: the wall clock's seconds).
pub fn device_config(mac: MacAddr, name: NameOfStation, boot_time: u32) -> DeviceConfig {
    DeviceConfig {
        mac,
        port_macs: port_macs(mac),
        name,
        ip: IpSuite::UNSET,
        im0: Im0::drive(SERIAL_NUMBER),
        im: ImData::default(),
        boot_time,
    }
}

/// A MAC written as `aa:bb:cc:dd:ee:ff` (as `/sys/class/net/IF/address`).
pub fn parse_mac(s: &str) -> Option<MacAddr> {
    let mut mac = [0u8; 6];
    let mut parts = s.trim().split(':');
    for b in mac.iter_mut() {
        *b = u8::from_str_radix(parts.next()?, 16).ok()?;
    }
    parts.next().is_none().then_some(MacAddr(mac))
}

/// `aa:bb:cc:dd:ee:ff`.
pub fn mac_text(mac: MacAddr) -> String {
    let m = mac.0;
    format!(
        "{:02x}:{:02x}:{:02x}:{:02x}:{:02x}:{:02x}",
        m[0], m[1], m[2], m[3], m[4], m[5]
    )
}

fn uuid_text(u: &Uuid) -> String {
    let hex: String = u.0.iter().map(|b| format!("{b:02x}")).collect();
    let part = |r: core::ops::Range<usize>| hex.get(r).unwrap_or_default().to_string();
    format!(
        "{}-{}-{}-{}-{}",
        part(0..8),
        part(8..12),
        part(12..16),
        part(16..20),
        part(20..32)
    )
}

fn suite_text(s: &IpSuite) -> String {
    if *s == IpSuite::UNSET {
        return "unset".into();
    }
    format!("{} mask {} gateway {}", s.ip, s.mask, s.gateway)
}

fn kept(permanent: bool) -> &'static str {
    if permanent {
        "permanent"
    } else {
        "temporary"
    }
}

/// One line for a device event, e.g. `DCP name of station "drive-1"
/// (permanent)`, `AR 1234…: connected`, `AR 1234…: aborted (Local)`.
pub fn describe(e: &DeviceEvent) -> String {
    match e {
        DeviceEvent::Dcp(DcpEvent::NameOfStation { name, permanent }) => {
            format!("DCP name of station \"{}\" ({})", name.as_str(), kept(*permanent))
        }
        DeviceEvent::Dcp(DcpEvent::IpSuite { suite, permanent }) => {
            format!("DCP IP {} ({})", suite_text(suite), kept(*permanent))
        }
        DeviceEvent::Dcp(DcpEvent::Signal { until }) => {
            format!("DCP signal (flashing until {:.3} s)", until.as_ns() as f64 / 1e9)
        }
        DeviceEvent::Dcp(DcpEvent::ResetToFactory(mode)) => format!("DCP reset to factory ({mode:?})"),
        DeviceEvent::Cm(CmEvent::Connected(u)) => format!("AR {}: connected", uuid_text(u)),
        DeviceEvent::Cm(CmEvent::PrmEnd(u)) => format!("AR {}: PrmEnd", uuid_text(u)),
        DeviceEvent::Cm(CmEvent::Ready(u)) => {
            format!("AR {}: ready (ApplicationReady confirmed)", uuid_text(u))
        }
        DeviceEvent::Cm(CmEvent::Released(u)) => format!("AR {}: released", uuid_text(u)),
        DeviceEvent::Cm(CmEvent::Aborted(u, why)) => format!("AR {}: aborted ({why:?})", uuid_text(u)),
        DeviceEvent::Cm(CmEvent::ImWritten(r)) => format!("I&M written ({r:?})"),
        DeviceEvent::Rt(RtEvent::Exchanging(u)) => format!("AR {}: cyclic data exchanged", uuid_text(u)),
        DeviceEvent::Rt(RtEvent::DataHoldExpired(u)) => {
            format!(
                "AR {}: data hold expired (outputs no longer current)",
                uuid_text(u)
            )
        }
        DeviceEvent::Rt(RtEvent::ArLost(u)) => {
            format!("AR {}: lost (cyclic watchdog or alarm channel)", uuid_text(u))
        }
    }
}

/// The simulated drive: the device and the loop-back of its process data.
pub struct PnDrive {
    device: Device,
}

impl PnDrive {
    /// A drive with `config` ([`device_config`]).
    pub fn new(config: DeviceConfig) -> PnDrive {
        PnDrive {
            device: Device::plain(config),
        }
    }

    /// The device (name, IP, AR, counters).
    pub fn device(&self) -> &Device {
        &self.device
    }

    /// The next event, oldest first.
    pub fn take_event(&mut self) -> Option<DeviceEvent> {
        self.device.take_event()
    }

    /// One received frame at `now`; answers go out through `tx`.
    pub fn receive(&mut self, now: Nanos, frame: &[u8], tx: &mut impl FnMut(&[u8])) {
        self.device.receive(now, frame, tx);
        self.echo();
    }

    /// The device's timers at `now`; returns when to call again at the latest.
    pub fn poll(&mut self, now: Nanos, tx: &mut impl FnMut(&[u8])) -> Nanos {
        self.echo();
        self.device.poll(now, tx)
    }

    /// The drive's application: the first IN module's current output data
    /// (controller → drive) is copied into the first OUT module's inputs
    /// (drive → controller), as far as both reach. Nothing changes while the
    /// outputs are not current.
    fn echo(&mut self) {
        let mut to_drive = None;
        let mut from_drive = None;
        for (slot, _, to) in self.device.data_modules() {
            match to {
                true if to_drive.is_none() => to_drive = Some(slot),
                false if from_drive.is_none() => from_drive = Some(slot),
                _ => {}
            }
        }
        let (Some(src), Some(dst)) = (to_drive, from_drive) else {
            return;
        };
        let mut buf = [0u8; MAX_MODULE_BYTES];
        let Some(n) = self.device.output_data(src).map(|d| {
            let n = d.len().min(buf.len());
            buf.get_mut(..n)
                .unwrap_or_default()
                .copy_from_slice(d.get(..n).unwrap_or_default());
            n
        }) else {
            return;
        };
        self.device.set_input_data(dst, buf.get(..n).unwrap_or_default());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn port_macs_are_locally_administered_variants_of_the_interface_mac() {
        let mac = MacAddr([0x00, 0x1b, 0x1b, 0x01, 0x02, 0xff]);
        let p = port_macs(mac);
        assert_eq!(p[0].0, [0x02, 0x1b, 0x1b, 0x01, 0x02, 0x00]);
        assert_eq!(p[1].0, [0x02, 0x1b, 0x1b, 0x01, 0x02, 0x01]);
        assert!(p.iter().all(|m| *m != mac));
    }

    #[test]
    fn a_mac_is_read_as_sysfs_writes_it() {
        let mac = parse_mac("aa:bb:cc:0d:0e:0f\n").unwrap();
        assert_eq!(mac.0, [0xaa, 0xbb, 0xcc, 0x0d, 0x0e, 0x0f]);
        assert_eq!(mac_text(mac), "aa:bb:cc:0d:0e:0f");
        assert!(parse_mac("aa:bb:cc:0d:0e").is_none());
        assert!(parse_mac("aa:bb:cc:0d:0e:0f:10").is_none());
    }

    /// profinet-py's Identify All as it leaves a veth (unpadded, 30 bytes)
    /// with the response delay factor `delay`.
    fn identify_all(delay: u8) -> Vec<u8> {
        let mut f = vec![0u8; 30];
        f[..6].copy_from_slice(&MacAddr::DCP_IDENTIFY.0);
        f[6..12].copy_from_slice(&[0xca, 0xf2, 0xc5, 0xb6, 0x1f, 0x9b]);
        f[12..14].copy_from_slice(&0x8892u16.to_be_bytes());
        f[14..30].copy_from_slice(&[
            0xFE, 0xFE, 0x05, 0x00, 0x11, 0x97, 0xab, 0x50, 0x00, delay, 0x00, 0x04, 0xFF, 0xFF, 0x00, 0x00,
        ]);
        f
    }

    /// The DCP frames a fresh drive sends within 1.3 s of an Identify All.
    fn identify_answers(delay: u8) -> Vec<Vec<u8>> {
        let mac = MacAddr([0x02, 0, 0, 0, 0, 0x42]);
        let mut d = PnDrive::new(device_config(mac, NameOfStation::EMPTY, 7));
        assert!(d.device().dcp().name_of_station().is_empty());
        assert_eq!(d.device().dcp().ip_suite(), IpSuite::UNSET);
        let mut out = Vec::new();
        d.receive(Nanos::ZERO, &identify_all(delay), &mut |b: &[u8]| {
            out.push(b.to_vec())
        });
        let next = d.poll(Nanos::ZERO, &mut |b: &[u8]| out.push(b.to_vec()));
        d.poll(next, &mut |b: &[u8]| out.push(b.to_vec()));
        d.poll(Nanos::from_ms(1300), &mut |b: &[u8]| out.push(b.to_vec()));
        out.retain(|b| b[6..12] == mac.0 && b[12..16] == [0x88, 0x92, 0xFE, 0xFF]);
        out
    }

    #[test]
    fn a_fresh_drive_answers_identify_at_once() {
        assert_eq!(identify_answers(1).len(), 1);
    }

    /// profinet-py asks with response delay factor 0x80 (up to 1.28 s): the
    /// delayed answer (140 bytes for the unnamed drive) is kept whole and
    /// sent when due.
    #[test]
    fn p008_a_fresh_drive_answers_a_delayed_identify() {
        assert_eq!(identify_answers(0x80).len(), 1);
    }
}
