//! The PROFINET operating parameters (spec §2.4) as the core's objects
//! A270…A278 ([`drive_core::params::PROFINET_PARAMS`]; type, range, default
//! and persistence are declared once, in `drive_core::objects`), and the
//! device settings built from them at start.
//!
//! | line | parameter | used |
//! |---|---|---|
//! | A270 | PROFINET active (BOOL, default 1) | read at start; a 0 takes effect at once ([`crate::PnDrive`]) |
//! | A271 | name of station (STRING(240), empty = none) | the device's name at start (P-007); DCP Set writes it |
//! | A272…A274 | static IP, subnet mask, gateway (UINT32, first octet in the MSB, 0 = none) | the device's IP suite at start (P-010); DCP Set writes them (P-009) |
//! | A275 | PROFIenergy active (BOOL, default 0) | record 0x80A0 served only while 1; 0 ends a pause ([`crate::energy`], P-015/P-016) |
//! | A276 | protocol (0 = standard protocol, range 0…0) | declared only: there is one protocol (P-014) |
//! | A277 | parameterisation interface (0 automatic, 1 on-board Ethernet, 2 PROFINET) | declared only (P-017) |
//! | A278 | vendor service port (UINT16, default 8802) | declared only: the vendor service protocol is not built (P-018) |

use core::net::Ipv4Addr;

use crate::Startup;
use drive_core::objects::LAYOUT_HASH;
use drive_core::params::{A271, A272, A273, A274};
use drive_core::{DriveObjects, PERSISTENT_IMAGE_BYTES};
use od::{CommState, Dictionary};
use profinet::cm::{Im0, ImData};
use profinet::dcp::server::ip_suite_valid;
use profinet::dcp::{IpSuite, NameOfStation};
use profinet::device::DeviceConfig;
use profinet::model;
use profinet::wire::MacAddr;
use store::{Flash, ParamStore};

/// The longest name of station in A271, bytes.
pub const NAME_LEN: usize = drive_core::objects::manufacturer::PN_NAME_LEN as usize;

/// What the board knows about the device apart from the parameters: the
/// production data and the boot counter.
#[derive(Clone, Debug)]
pub struct Hardware {
    /// The interface MAC (DCP, IP, RT).
    pub mac: MacAddr,
    /// The port MACs (LLDP sources, P-006).
    pub port_macs: [MacAddr; model::PORTS as usize],
    /// I&M0 (identity).
    pub im0: Im0,
    /// I&M1–4 of a board whose parameter store holds none yet (the store's
    /// take precedence: [`crate::PnDrive`] keeps them behind the parameter
    /// image, [`im_trailer`]).
    pub im: ImData,
    /// The RPC server boot time: different after every start.
    pub boot_time: u32,
}

impl From<DeviceConfig> for Hardware {
    /// The board's part of a device configuration (its MACs, I&M and boot
    /// time; the name and IP suite are the parameters'): what
    /// [`device_config`] builds a configuration from again.
    fn from(c: DeviceConfig) -> Hardware {
        Hardware {
            mac: c.mac,
            port_macs: c.port_macs,
            im0: c.im0,
            im: c.im,
            boot_time: c.boot_time,
        }
    }
}

/// Length of I&M1…4 in the store: IM_Tag_Function (32), IM_Tag_Location
/// (22), IM_Date (16), IM_Descriptor (54), IM_Signature (54).
pub const IM_BYTES: usize = 32 + 22 + 16 + 54 + 54;
/// What follows the parameter image in the store: I&M1…4, then this tag.
pub const IM_TAG: [u8; 4] = *b"IM14";
/// Length of that trailer.
pub const IM_TRAILER: usize = IM_BYTES + IM_TAG.len();

/// I&M1…4 as the trailer stored behind the parameter image.
pub fn im_trailer(im: &ImData) -> [u8; IM_TRAILER] {
    let mut out = [0u8; IM_TRAILER];
    let parts: [&[u8]; 6] = [
        &im.tag_function,
        &im.tag_location,
        &im.date,
        &im.descriptor,
        &im.signature,
        &IM_TAG,
    ];
    let mut at = 0;
    for p in parts {
        if let Some(dst) = out.get_mut(at..at + p.len()) {
            dst.copy_from_slice(p);
        }
        at += p.len();
    }
    out
}

/// Splits a stored record into the parameter image and I&M1…4 (`None`: a
/// record saved before I&M were kept, or without the tag).
pub fn split_stored(record: &[u8]) -> (&[u8], Option<ImData>) {
    let Some(at) = record.len().checked_sub(IM_TRAILER) else {
        return (record, None);
    };
    let (params, trailer) = record.split_at(at);
    if trailer.get(IM_BYTES..) != Some(&IM_TAG[..]) {
        return (record, None);
    }
    let mut im = ImData::default();
    let mut at = 0;
    for dst in [
        &mut im.tag_function[..],
        &mut im.tag_location[..],
        &mut im.date[..],
        &mut im.descriptor[..],
        &mut im.signature[..],
    ] {
        let n = dst.len();
        if let Some(src) = trailer.get(at..at + n) {
            dst.copy_from_slice(src);
        }
        at += n;
    }
    (params, Some(im))
}

/// The name of station in A271 into `buf`; returns its length (0 when the
/// object does not read).
pub(crate) fn name_bytes(objects: &mut DriveObjects, buf: &mut [u8; NAME_LEN]) -> usize {
    // A271 is a string: read through the dictionary's checked path (level 0,
    // visible at every access level)
    objects.read(A271, 0, buf, CommState::PreOp).unwrap_or(0)
}

/// The stored name of station (A271); a name that breaks the
/// name-of-station rules counts as none (the drive starts unnamed).
pub fn name_of_station(objects: &mut DriveObjects) -> NameOfStation {
    let mut buf = [0u8; NAME_LEN];
    let n = name_bytes(objects, &mut buf);
    buf.get(..n)
        .and_then(|b| NameOfStation::new(b).ok())
        .unwrap_or(NameOfStation::EMPTY)
}

/// Writes `name` into A271 (RAM; the rest of the string is zeroed).
pub fn write_name(objects: &mut DriveObjects, name: &NameOfStation) {
    let _ = objects.set_bytes(A271, 0, name.as_bytes());
}

fn addr(objects: &DriveObjects, index: u16) -> Ipv4Addr {
    let v = objects.get(index, 0).unwrap_or(0);
    Ipv4Addr::from(u32::try_from(v).unwrap_or(0))
}

/// The stored static IP suite (A272…A274); a suite DCP would refuse (see
/// [`ip_suite_valid`]) counts as none.
pub fn ip_suite(objects: &DriveObjects) -> IpSuite {
    let s = stored_ip(objects);
    if ip_suite_valid(&s) {
        s
    } else {
        IpSuite::UNSET
    }
}

/// A272…A274 as they are, valid or not.
pub(crate) fn stored_ip(objects: &DriveObjects) -> IpSuite {
    IpSuite {
        ip: addr(objects, A272),
        mask: addr(objects, A273),
        gateway: addr(objects, A274),
    }
}

/// Writes `suite` into A272…A274 (RAM).
pub fn write_ip(objects: &mut DriveObjects, suite: IpSuite) {
    for (index, a) in [(A272, suite.ip), (A273, suite.mask), (A274, suite.gateway)] {
        let _ = objects.set(index, 0, i64::from(u32::from(a)));
    }
}

/// The device settings at start: name and IP from the objects, the rest
/// from `hw`.
pub fn device_config(objects: &mut DriveObjects, hw: Hardware) -> DeviceConfig {
    DeviceConfig {
        mac: hw.mac,
        port_macs: hw.port_macs,
        name: name_of_station(objects),
        ip: ip_suite(objects),
        im0: hw.im0,
        im: hw.im,
        boot_time: hw.boot_time,
    }
}

/// What sits between the parameter image and I&M1…4 in the store: sysContact,
/// sysName and sysLocation of the SNMP agent (P-038), each a length byte and
/// 255 bytes, then this tag.
pub const SNMP_TAG: [u8; 4] = *b"SNMP";
/// Length of that block.
pub const SNMP_BLOCK: usize = 3 * (1 + snmp::TEXT_MAX) + SNMP_TAG.len();

/// The SNMP agent's kept strings as the block stored behind the parameter image.
pub fn snmp_block(a: &snmp::Agent) -> [u8; SNMP_BLOCK] {
    let mut out = [0u8; SNMP_BLOCK];
    let mut at = 0;
    for t in [&a.sys_contact, &a.sys_name, &a.sys_location] {
        let s = t.get();
        if let Some(l) = out.get_mut(at) {
            *l = s.len() as u8;
        }
        if let Some(dst) = out.get_mut(at + 1..at + 1 + s.len()) {
            dst.copy_from_slice(s);
        }
        at += 1 + snmp::TEXT_MAX;
    }
    if let Some(dst) = out.get_mut(at..) {
        dst.copy_from_slice(&SNMP_TAG);
    }
    out
}

/// Splits the SNMP block off the end of `params` (`None`: saved before it was kept).
pub fn split_snmp(params: &[u8]) -> (&[u8], Option<snmp::Agent>) {
    let Some(at) = params.len().checked_sub(SNMP_BLOCK) else {
        return (params, None);
    };
    let (rest, block) = params.split_at(at);
    if block.get(SNMP_BLOCK - SNMP_TAG.len()..) != Some(&SNMP_TAG[..]) {
        return (params, None);
    }
    let mut a = snmp::Agent::default();
    let mut at = 0;
    for dst in [&mut a.sys_contact, &mut a.sys_name, &mut a.sys_location] {
        let n = usize::from(block.get(at).copied().unwrap_or(0));
        if let Some(t) = block.get(at + 1..at + 1 + n).and_then(snmp::Text::new) {
            *dst = t;
        }
        at += 1 + snmp::TEXT_MAX;
    }
    (rest, Some(a))
}

/// The store's record: the parameter image and I&M1…4 behind it.
pub const STORED_BYTES: usize = PERSISTENT_IMAGE_BYTES + SNMP_BLOCK + IM_TRAILER;

/// The parameter flash of the PROFINET images: two slots of two 2 KiB
/// sectors, as the parameter image with I&M1…4 behind it
/// ([`STORED_BYTES`]) no longer fits one 2 KiB sector (the EtherCAT
/// images' `firmware_tasks::ParamFlash`). In RAM until the board's PFLASH driver is
/// used, like that one.
pub type PnParamFlash = store::RamFlash<2048, 4>;

/// Loads the newest saved set into `objects` (defaults stay when there is
/// none, it is from another declaration or does not load); the I&M1…4 and
/// the SNMP agent's values saved with it.
pub(crate) fn load<F: Flash>(
    store: &mut ParamStore<F>,
    objects: &mut DriveObjects,
) -> (Startup, Option<ImData>, Option<snmp::Agent>) {
    let mut image = [0u8; STORED_BYTES];
    let Ok(n) = store.load(LAYOUT_HASH, &mut image) else {
        return (Startup::Defaults, None, None);
    };
    let (params, im) = split_stored(image.get(..n).unwrap_or(&[]));
    let (params, kept) = split_snmp(params);
    match objects.load_persistent(params) {
        Ok(()) => (Startup::Loaded, im, kept),
        Err(_) => (Startup::Defaults, None, None),
    }
}
