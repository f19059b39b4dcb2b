//! The drive's ESI (EtherCAT Slave Information, ETG.2000 `EtherCATInfo` XML),
//! generated from the one declaration: [`drive_ecat::DEVICE`] (identity,
//! SyncManagers, FMMUs, PDOs, DC op modes, mailbox), the object dictionary
//! [`drive_ecat::objects::OBJECTS`] (through [`drive_ecat::DriveObjects`], so the ESI
//! lists exactly what the device shows in each subindex template) and the SII
//! builder [`ecat::build_sii`] (EEPROM size, ConfigData, bootstrap mailbox).
//!
//! One file per device and subindex template (E-150): the double-axis device
//! ([`drive_ecat::DEVICE`], SC6A062) and the single-axis device
//! ([`drive_ecat::DEVICE_SINGLE`], SI6A061, [`Variant::Single`]: no axis-B
//! objects or PDOs), each in "EtherCAT Rx SDO Info" (the default) and
//! "EtherCAT Rx", each with the revision number 1018h:03 of its template
//! (E-151, [`drive_ecat::revision`]). The checked-in files under `esi/`
//! are kept equal to [`files`] by the test `esi_files_are_current`
//! (`UPDATE_ESI=1 cargo test -p esi` rewrites them; `cargo run -p esi` too).
//!
//! Each ESI is modular (E-149): one slot per axis ([`slots`]), each allowing
//! the system modules of that axis, one per application layout
//! ([`drive_ecat::PdoLayout::ALL`], the standard layout the default), with their
//! own PDO indexes and entries ([`Module`]) and the idents F050h reports
//! ([`drive_ecat::module_ident`], E-148). The device-level PDOs stay the default
//! configuration the SII carries, marked `OverwrittenByModule` where a
//! slot's module describes the same PDO (docs/esi.md).
//!
//! A host tool: it uses `std` (`String`, `BTreeMap`).

use std::collections::BTreeMap;
use std::fmt::Write;

use drive_ecat::{revision, DriveObjects, PdoLayout, Template, Variant};
use ecat::desc::{coe_details, DcOpMode, Device};
use ecat::sii::EEPROM_BYTES;
use esc::sii::{mailbox_protocol, word};
use od::PdoEntry;
use od::{Access, DataType, Dictionary, EntryInfo, ObjectCode, ObjectInfo};

/// Vendor name of vendor ID B9h (spec §18).
pub const VENDOR_NAME: &str = "STOBER Antriebstechnik GmbH + Co. KG";

/// The subindex templates, each with its own ESI (E-150).
pub const TEMPLATES: [Template; 2] = [Template::SdoInfo, Template::Rx];

/// Bytes of the SII's ESC configuration area that the ESI's `ConfigData`
/// repeats (words 0..6; the master computes the checksum, word 7).
pub const CONFIG_DATA_BYTES: usize = 14;

/// The template's name as the manual writes it.
pub const fn template_name(template: Template) -> &'static str {
    match template {
        Template::SdoInfo => "EtherCAT Rx SDO Info",
        Template::Rx => "EtherCAT Rx",
    }
}

/// The devices, each with its own ESIs (the double-axis device first).
pub const VARIANTS: [Variant; 2] = Variant::ALL;

/// File name of the ESI of `variant` in `template` under `esi/` (named
/// after the order code).
pub fn file_name(variant: Variant, template: Template) -> String {
    let suffix = match template {
        Template::SdoInfo => "rx-sdo-info",
        Template::Rx => "rx",
    };
    format!("{}-{suffix}.xml", drive_ecat::device(variant).order_code)
}

/// The description of `variant` in `template`: [`drive_ecat::device`] with the
/// template's revision number (E-151) and, for "EtherCAT Rx", without SDO
/// Information. In the default template this is [`drive_ecat::device`] itself
/// (the SII the drive carries); the SII of the "EtherCAT Rx" template is
/// `build_sii` of this.
pub fn device(variant: Variant, template: Template) -> Device {
    let mut d = *drive_ecat::device(variant);
    d.identity.revision = revision(template);
    if template == Template::Rx {
        d.coe_details &= !coe_details::SDO_INFO;
    }
    d
}

/// The SII image of `variant` in `template` ([`EEPROM_BYTES`] long).
pub fn sii(variant: Variant, template: Template) -> Result<Vec<u8>, ecat::SiiError> {
    let mut img = vec![0u8; EEPROM_BYTES];
    ecat::build_sii(&device(variant, template), &mut img)?;
    Ok(img)
}

/// The object dictionary of `variant` as the bus sees it in `template`, at
/// the default access level (A10\[2\]): the objects and entries the ESI
/// lists.
pub fn dictionary(variant: Variant, template: Template) -> DriveObjects {
    let mut d = DriveObjects::for_variant(variant);
    d.set_template(template);
    d
}

/// A system module of the ESI (E-149): one application layout on one axis,
/// its PDOs in the axis's channel (1600h/1A00h + axis) with the layout's
/// entries on that axis (axis B's objects at +800h/+8000h), so each slot's
/// modules carry their own indexes rather than one `SlotIndexIncrement`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Module {
    /// The axis (0 = A, 1 = B): the slot the module goes in.
    pub axis: u16,
    /// The layout.
    pub layout: PdoLayout,
}

impl Module {
    /// The ident (`Type@ModuleIdent`), as F050h reports it for this axis
    /// when its channel carries the layout (E-148).
    pub const fn ident(&self) -> u32 {
        drive_ecat::module_ident(self.layout, self.axis)
    }

    /// The RxPDO (channel 1 + axis) and TxPDO indexes.
    pub const fn pdo_indexes(&self) -> (u16, u16) {
        (0x1600 + self.axis, 0x1A00 + self.axis)
    }

    /// The RxPDO and TxPDO entries.
    pub const fn entries(&self) -> (&'static [PdoEntry], &'static [PdoEntry]) {
        self.layout.axis_entries(self.axis)
    }

    /// Is this the default module of its slot (the standard layout, what the
    /// channel carries by default)?
    pub fn is_default(&self) -> bool {
        self.layout == PdoLayout::Standard
    }
}

/// The axis's letter.
pub const fn axis_letter(axis: u16) -> char {
    if axis == 0 {
        'A'
    } else {
        'B'
    }
}

/// The slots of `variant`: one per axis (axis A; and axis B on the
/// double-axis device), each with the modules it allows (every layout on
/// that axis, [`PdoLayout::ALL`] order, the standard layout first).
pub fn slots(variant: Variant) -> Vec<Vec<Module>> {
    (0..variant.axes() as u16)
        .map(|axis| {
            PdoLayout::ALL
                .iter()
                .map(|&layout| Module { axis, layout })
                .collect()
        })
        .collect()
}

/// Every generated file: (file name, contents), per device and template.
pub fn files() -> Result<Vec<(String, String)>, Error> {
    VARIANTS
        .iter()
        .flat_map(|&v| TEMPLATES.iter().map(move |&t| (v, t)))
        .map(|(v, t)| Ok((file_name(v, t), generate(v, t)?)))
        .collect()
}

/// Why the ESI could not be generated.
#[derive(Debug)]
pub enum Error {
    /// The SII image could not be built.
    Sii(ecat::SiiError),
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Sii(e) => write!(f, "SII image: {e:?}"),
        }
    }
}

impl std::error::Error for Error {}

/// The ESI of `variant` in `template`.
pub fn generate(variant: Variant, template: Template) -> Result<String, Error> {
    let dev = device(variant, template);
    let image = sii(variant, template).map_err(Error::Sii)?;
    let od = dictionary(variant, template);
    let source = match variant {
        Variant::Double => "drive_ecat::DEVICE",
        Variant::Single => "drive_ecat::DEVICE_SINGLE",
    };
    let mut x = Xml::default();
    x.raw("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.raw(&format!(
        "<!-- Generated by crates/esi from {source} and the object dictionary; do not edit.\n     \
         Regenerate: UPDATE_ESI=1 cargo test -p esi (or cargo run -p esi). Template \"{}\". -->\n",
        template_name(template)
    ));
    x.open(
        "EtherCATInfo",
        &[
            ("xmlns:xsi", "http://www.w3.org/2001/XMLSchema-instance"),
            ("xsi:noNamespaceSchemaLocation", "EtherCATInfo.xsd"),
            ("Version", "1.6"),
        ],
    );
    x.open("Vendor", &[]);
    x.leaf("Id", &[], &hex32(dev.identity.vendor_id));
    x.leaf("Name", &[("LcId", "1033")], VENDOR_NAME);
    x.close("Vendor");
    x.open("Descriptions", &[]);
    x.open("Groups", &[]);
    x.open("Group", &[]);
    x.leaf("Type", &[], dev.group);
    x.leaf("Name", &[("LcId", "1033")], dev.group);
    x.close("Group");
    x.close("Groups");
    x.open("Devices", &[]);
    let slots = slots(variant);
    device_element(&mut x, &dev, template, &image, &od, &slots);
    x.close("Devices");
    x.open("Modules", &[]);
    for m in slots.iter().flatten() {
        module_element(&mut x, &dev, m);
    }
    x.close("Modules");
    x.close("Descriptions");
    x.close("EtherCATInfo");
    Ok(x.out)
}

fn device_element(
    x: &mut Xml,
    dev: &Device,
    template: Template,
    image: &[u8],
    od: &DriveObjects,
    slots: &[Vec<Module>],
) {
    let physics = "Y".repeat(usize::from(dev.ports));
    x.open("Device", &[("Physics", &physics)]);
    x.leaf(
        "Type",
        &[
            ("ProductCode", &hex32(dev.identity.product_code)),
            ("RevisionNo", &hex32(dev.identity.revision)),
        ],
        dev.order_code,
    );
    x.leaf(
        "Name",
        &[("LcId", "1033")],
        &format!("{} {} ({})", dev.name, dev.order_code, template_name(template)),
    );
    // ETG.1000.6 explicit device identification: the ID (the station
    // alias) in register 0x0134 on an ID request (issue 33)
    x.open("Info", &[]);
    x.leaf("IdentificationReg134", &[], "true");
    x.close("Info");
    x.leaf("GroupType", &[], dev.group);

    x.open("Profile", &[]);
    x.leaf("ProfileNo", &[], &(dev.device_type & 0xFFFF).to_string());
    x.leaf("AddInfo", &[], &(dev.device_type >> 16).to_string());
    dictionary_element(x, template, od);
    x.close("Profile");

    // Trailing unused FMMUs are left out (the ESI names only used ones).
    let used = dev
        .fmmus
        .iter()
        .rposition(|f| *f != ecat::FmmuUsage::Unused)
        .map_or(0, |i| i + 1);
    for f in dev.fmmus.iter().take(used) {
        let usage = match f {
            ecat::FmmuUsage::Outputs => "Outputs",
            ecat::FmmuUsage::Inputs => "Inputs",
            ecat::FmmuUsage::MailboxStatus => "MBoxState",
            ecat::FmmuUsage::Unused => "",
        };
        x.leaf("Fmmu", &[], usage);
    }
    let sms = [
        (
            dev.mailbox_out.start,
            usize::from(dev.mailbox_out.length),
            dev.mailbox_out.control,
            "MBoxOut",
        ),
        (
            dev.mailbox_in.start,
            usize::from(dev.mailbox_in.length),
            dev.mailbox_in.control,
            "MBoxIn",
        ),
        (
            dev.outputs.start,
            dev.output_bytes(),
            dev.outputs.control,
            "Outputs",
        ),
        (dev.inputs.start, dev.input_bytes(), dev.inputs.control, "Inputs"),
    ];
    for (start, size, control, kind) in sms {
        x.leaf(
            "Sm",
            &[
                ("DefaultSize", &size.to_string()),
                ("StartAddress", &hex16(start)),
                ("ControlByte", &format!("#x{control:02X}")),
                ("Enable", "1"),
            ],
            kind,
        );
    }
    // the default configuration (the SII's PDOs); a slot's module with the
    // same index replaces the PDO for a master that configures modules
    let in_module = |index: u16| {
        slots.iter().flatten().any(|m| {
            let (rx, tx) = m.pdo_indexes();
            index == rx || index == tx
        })
    };
    for (tag, pdos, assign, sm) in [
        ("RxPdo", dev.rx_pdos, dev.rx_assign, 2),
        ("TxPdo", dev.tx_pdos, dev.tx_assign, 3),
    ] {
        for pdo in pdos {
            let mut attrs = pdo_attrs(dev, assign.contains(&pdo.index), sm);
            if in_module(pdo.index) {
                attrs.push(("OverwrittenByModule", "1".into()));
            }
            pdo_element(x, tag, &attrs, pdo.index, pdo.name, pdo.entries);
        }
    }

    let flag = |b: bool| if b { "1" } else { "0" };
    x.open("Mailbox", &[("DataLinkLayer", "1")]);
    if dev.mailbox_protocols & mailbox_protocol::AOE != 0 {
        x.empty("AoE", &[]);
    }
    if dev.mailbox_protocols & mailbox_protocol::EOE != 0 {
        x.empty("EoE", &[("IP", "1"), ("MAC", "1")]);
    }
    if dev.mailbox_protocols & mailbox_protocol::COE != 0 {
        let c = dev.coe_details;
        x.empty(
            "CoE",
            &[
                ("SdoInfo", flag(c & coe_details::SDO_INFO != 0)),
                ("PdoAssign", flag(c & coe_details::PDO_ASSIGN != 0)),
                ("PdoConfig", flag(c & coe_details::PDO_CONFIG != 0)),
                ("PdoUpload", flag(c & coe_details::UPLOAD_AT_STARTUP != 0)),
                ("CompleteAccess", flag(c & coe_details::SDO_COMPLETE_ACCESS != 0)),
                ("SegmentedSdo", "1"),
            ],
        );
    }
    if dev.mailbox_protocols & mailbox_protocol::FOE != 0 {
        x.empty("FoE", &[]);
    }
    if dev.mailbox_protocols & mailbox_protocol::SOE != 0 {
        x.empty("SoE", &[]);
    }
    x.close("Mailbox");

    if dev.dc_supported() {
        x.open("Dc", &[]);
        for m in dc_modes(dev) {
            x.open("OpMode", &[]);
            x.leaf("Name", &[], m.name);
            x.leaf("Desc", &[], m.description);
            x.leaf("AssignActivate", &[], &hex16(m.assign_activate));
            if m.assign_activate != 0 {
                x.leaf(
                    "CycleTimeSync0",
                    &[("Factor", &m.sync0_cycle_factor.to_string())],
                    &m.cycle_time_ns.to_string(),
                );
                x.leaf("ShiftTimeSync0", &[], &m.shift_ns.to_string());
            }
            x.close("OpMode");
        }
        x.close("Dc");
    }

    // one slot per axis, its modules by ident, the standard layout the default
    x.open("Slots", &[]);
    for (axis, modules) in slots.iter().enumerate() {
        x.open("Slot", &[("MinInstances", "1"), ("MaxInstances", "1")]);
        x.leaf(
            "Name",
            &[("LcId", "1033")],
            &format!("Axis {}", axis_letter(axis as u16)),
        );
        for m in modules {
            if m.is_default() {
                x.leaf("ModuleIdent", &[("Default", "1")], &hex32(m.ident()));
            } else {
                x.leaf("ModuleIdent", &[], &hex32(m.ident()));
            }
        }
        x.close("Slot");
    }
    x.close("Slots");

    x.open("Eeprom", &[]);
    x.leaf("ByteSize", &[], &EEPROM_BYTES.to_string());
    x.leaf(
        "ConfigData",
        &[],
        &hex_bytes(image.get(..CONFIG_DATA_BYTES).unwrap_or(&[])),
    );
    let boot = usize::from(word::BOOT_RX_MAILBOX_OFFSET) * 2;
    x.leaf(
        "BootStrap",
        &[],
        &hex_bytes(image.get(boot..boot + 8).unwrap_or(&[])),
    );
    x.close("Eeprom");
    x.close("Device");
}

/// The DC op modes in ESI order: the SYNC0 modes (assign-activate ≠ 0)
/// first, so "DC enabled (SYNC0)" is the master's default (E-108), then the
/// others (SM-synchronous, free run) in declaration order.
pub fn dc_modes(dev: &Device) -> Vec<&'static DcOpMode> {
    let sync0 = dev.dc_modes.iter().filter(|m| m.assign_activate != 0);
    let other = dev.dc_modes.iter().filter(|m| m.assign_activate == 0);
    sync0.chain(other).collect()
}

/// The attributes of a PDO: `Fixed` only without PDO configuration,
/// `Mandatory` for an assigned PDO only without PDO assignment, `Sm` when
/// assigned.
fn pdo_attrs(dev: &Device, assigned: bool, sm: u8) -> Vec<(&'static str, String)> {
    let mut attrs = Vec::new();
    if dev.coe_details & coe_details::PDO_CONFIG == 0 {
        attrs.push(("Fixed", "1".into()));
    }
    if assigned && dev.coe_details & coe_details::PDO_ASSIGN == 0 {
        attrs.push(("Mandatory", "1".into()));
    }
    if assigned {
        attrs.push(("Sm", sm.to_string()));
    }
    attrs
}

fn pdo_element(
    x: &mut Xml,
    tag: &str,
    attrs: &[(&str, String)],
    index: u16,
    name: &str,
    entries: &[PdoEntry],
) {
    let attrs: Vec<(&str, &str)> = attrs.iter().map(|(k, v)| (*k, v.as_str())).collect();
    x.open(tag, &attrs);
    x.leaf("Index", &[], &hex16(index));
    x.leaf("Name", &[], name);
    for e in entries {
        x.open("Entry", &[]);
        x.leaf("Index", &[], &hex16(e.index));
        x.leaf("SubIndex", &[], &e.sub.to_string());
        x.leaf("BitLen", &[], &e.bits().to_string());
        x.leaf("Name", &[], e.name);
        x.leaf("DataType", &[], e.data_type.esi_name());
        x.close("Entry");
    }
    x.close(tag);
}

/// A module (E-149): its ident and names, its RxPDO and TxPDO in the axis's
/// channel, assigned (`Sm`) when the module is in its slot, named as the
/// device names the channel's PDOs.
fn module_element(x: &mut Xml, dev: &Device, m: &Module) {
    let letter = axis_letter(m.axis);
    x.open("Module", &[]);
    x.leaf(
        "Type",
        &[("ModuleIdent", &hex32(m.ident()))],
        &format!("{} axis {letter} {}", dev.name, m.layout.name()),
    );
    x.leaf(
        "Name",
        &[("LcId", "1033")],
        &format!("Axis {letter}: {}", m.layout.name()),
    );
    let (rx_index, tx_index) = m.pdo_indexes();
    let (rx, tx) = m.entries();
    for (tag, index, entries, sm) in [("RxPdo", rx_index, rx, 2), ("TxPdo", tx_index, tx, 3)] {
        let name = dev.pdo(index).map_or("", |p| p.name);
        pdo_element(x, tag, &pdo_attrs(dev, true, sm), index, name, entries);
    }
    x.close("Module");
}

/// The ESI name of a data type: the ETG base type names, `STRING(n)` and
/// `ARRAY [0..n-1] OF BYTE` for strings.
pub fn type_name(t: DataType) -> String {
    match t {
        DataType::VisibleString(n) => format!("STRING({n})"),
        DataType::OctetString(n) => format!("ARRAY [0..{}] OF BYTE", n.saturating_sub(1)),
        _ => t.esi_name().to_string(),
    }
}

/// The data type name of an ARRAY/RECORD object.
pub fn object_type_name(index: u16) -> String {
    format!("DT{index:04X}")
}

/// The objects the ESI lists in `template`: what the device's SDO Info
/// object list shows at the default access level.
pub fn listed_objects(od: &DriveObjects) -> Vec<&'static ObjectInfo> {
    let mut out = Vec::new();
    let mut after = None;
    while let Some(o) = od.next_object(after) {
        out.push(o);
        after = Some(o.index);
    }
    out
}

/// Is `o` written as a single VAR (one entry, sub 0)?
pub fn is_var(o: &ObjectInfo) -> bool {
    o.code == ObjectCode::Var && o.entries.len() == 1 && o.entries.get(0).is_some_and(|e| e.sub == 0)
}

/// Bit offsets of the entries of an ARRAY/RECORD and its total size: sub 0
/// at 0, the elements from bit 16 on, entries of 16 bits or more aligned to
/// 16 bits (the usual ESI layout), the total rounded up to 16 bits.
pub fn layout(entries: &[EntryInfo]) -> (Vec<u32>, u32) {
    let mut offs = Vec::with_capacity(entries.len());
    let mut at = 0u32;
    for (i, e) in entries.iter().enumerate() {
        let bits = u32::from(e.bit_len());
        if i == 1 {
            at = at.max(16);
        }
        if bits >= 16 {
            at = at.div_ceil(16) * 16;
        }
        offs.push(at);
        at += bits;
    }
    (offs, at.div_ceil(16) * 16)
}

fn dictionary_element(x: &mut Xml, template: Template, od: &DriveObjects) {
    let objects = listed_objects(od);
    // Base types and string types first (sorted), then the object types.
    let mut base: BTreeMap<String, DataType> = BTreeMap::new();
    for o in &objects {
        for e in o.entries {
            base.insert(type_name(e.data_type), e.data_type);
        }
    }
    x.open("Dictionary", &[]);
    x.open("DataTypes", &[]);
    if base.values().any(|t| matches!(t, DataType::OctetString(_))) {
        x.open("DataType", &[]);
        x.leaf("Name", &[], "BYTE");
        x.leaf("BitSize", &[], "8");
        x.close("DataType");
    }
    for (name, t) in &base {
        x.open("DataType", &[]);
        x.leaf("Name", &[], name);
        // EtherCATInfo.xsd: Name, BaseType, BitSize, ArrayInfo in this order
        if let DataType::OctetString(_) = t {
            x.leaf("BaseType", &[], "BYTE");
        }
        x.leaf("BitSize", &[], &t.bits().to_string());
        if let DataType::OctetString(n) = t {
            x.open("ArrayInfo", &[]);
            x.leaf("LBound", &[], "0");
            x.leaf("Elements", &[], &n.to_string());
            x.close("ArrayInfo");
        }
        x.close("DataType");
    }
    for o in objects.iter().filter(|o| !is_var(o)) {
        let entries: Vec<EntryInfo> = o.entries.iter().collect();
        let (offs, size) = layout(&entries);
        x.open("DataType", &[]);
        x.leaf("Name", &[], &object_type_name(o.index));
        x.leaf("BitSize", &[], &size.to_string());
        for (e, off) in o.entries.iter().zip(offs) {
            x.open("SubItem", &[]);
            x.leaf("SubIdx", &[], &e.sub.to_string());
            x.leaf("Name", &[], e.name);
            x.leaf("Type", &[], &type_name(e.data_type));
            x.leaf("BitSize", &[], &e.bit_len().to_string());
            x.leaf("BitOffs", &[], &off.to_string());
            flags(x, e.access, e.persistent);
            x.close("SubItem");
        }
        x.close("DataType");
    }
    x.close("DataTypes");

    x.open("Objects", &[]);
    for o in &objects {
        x.open("Object", &[]);
        x.leaf("Index", &[], &hex16(o.index));
        x.leaf("Name", &[], o.name);
        let entries: Vec<EntryInfo> = o.entries.iter().collect();
        if let (true, [e]) = (is_var(o), entries.as_slice()) {
            x.leaf("Type", &[], &type_name(e.data_type));
            x.leaf("BitSize", &[], &e.bit_len().to_string());
            x.open("Info", &[]);
            default_value(x, od, o, e, template);
            x.close("Info");
            flags(x, e.access, e.persistent);
        } else {
            x.leaf("Type", &[], &object_type_name(o.index));
            x.leaf("BitSize", &[], &layout(&entries).1.to_string());
            x.open("Info", &[]);
            for e in &entries {
                x.open("SubItem", &[]);
                x.leaf("Name", &[], e.name);
                x.open("Info", &[]);
                default_value(x, od, o, e, template);
                x.close("Info");
                x.close("SubItem");
            }
            x.close("Info");
            let sub0 = entries.first().map_or(Access::RO, |e| e.access);
            flags(x, Access(sub0.0 & (Access::READ | Access::WRITE)), false);
        }
        x.close("Object");
    }
    x.close("Objects");
    x.close("Dictionary");
}

/// The default of entry `e` of `o`: the declared default (the device's
/// declaration, as `od` shows it); 1018h:03 is the template's revision
/// (E-151); constant strings as `DefaultString`.
fn default_value(x: &mut Xml, od: &DriveObjects, o: &ObjectInfo, e: &EntryInfo, template: Template) {
    let value = if o.index == 0x1018 && e.sub == 3 {
        i64::from(revision(template))
    } else {
        e.default
    };
    if e.data_type.is_string() {
        if let Some(s) = constant_text(od, o.index) {
            x.leaf("DefaultString", &[], s);
        }
        return;
    }
    let mut buf = [0u8; 8];
    let n = e.data_type.encode(value, &mut buf).unwrap_or(0);
    x.leaf("DefaultData", &[], &hex_bytes(buf.get(..n).unwrap_or(&[])));
}

/// The constant text of a VAR string object (1008h, 1009h, 100Ah, …) as
/// the device declares it.
fn constant_text(od: &DriveObjects, index: u16) -> Option<&'static str> {
    match od.declared_object(index)?.value {
        drive_ecat::objects::Value::Text(s) => Some(s),
        _ => None,
    }
}

/// `Flags` of an entry: `Access` (ro/rw/wo, `WriteRestrictions="PreOP"` when
/// written in Pre-Operational only), `PdoMapping` (R, T, RT), `Backup` for
/// entries saved by "save values" (1010h / A00).
fn flags(x: &mut Xml, a: Access, persistent: bool) {
    x.open("Flags", &[]);
    let (text, restrict) = access_text(a);
    match restrict {
        Some(r) => x.leaf("Access", &[("WriteRestrictions", r)], text),
        None => x.leaf("Access", &[], text),
    }
    if let Some(m) = pdo_mapping(a) {
        x.leaf("PdoMapping", &[], m);
    }
    if persistent || a.0 & Access::BACKUP != 0 {
        x.leaf("Backup", &[], "1");
    }
    if a.0 & Access::SETTING != 0 {
        x.leaf("Setting", &[], "1");
    }
    x.close("Flags");
}

/// The ESI access text and write restriction of `a`.
pub fn access_text(a: Access) -> (&'static str, Option<&'static str>) {
    match (a.readable(), a.writable()) {
        (true, false) => ("ro", None),
        (false, _) => ("wo", None),
        (true, true) => match (a.writable_in(0), a.writable_in(1), a.writable_in(2)) {
            (true, true, true) => ("rw", None),
            (true, false, false) => ("rw", Some("PreOP")),
            (true, true, false) => ("rw", Some("PreOP_SafeOP")),
            (true, false, true) => ("rw", Some("PreOP_OP")),
            (false, true, false) => ("rw", Some("SafeOP")),
            (false, true, true) => ("rw", Some("SafeOP_OP")),
            (false, false, _) => ("rw", Some("OP")),
        },
    }
}

/// The ESI `PdoMapping` of `a`.
pub fn pdo_mapping(a: Access) -> Option<&'static str> {
    match (a.rx_mappable(), a.tx_mappable()) {
        (true, true) => Some("RT"),
        (true, false) => Some("R"),
        (false, true) => Some("T"),
        (false, false) => None,
    }
}

fn hex16(v: u16) -> String {
    format!("#x{v:04X}")
}

fn hex32(v: u32) -> String {
    format!("#x{v:08X}")
}

fn hex_bytes(b: &[u8]) -> String {
    b.iter().fold(String::new(), |mut s, b| {
        let _ = write!(s, "{b:02X}");
        s
    })
}

/// A small indenting XML writer.
#[derive(Default)]
struct Xml {
    out: String,
    depth: usize,
}

impl Xml {
    fn raw(&mut self, s: &str) {
        self.out.push_str(s);
    }

    fn start(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        for _ in 0..self.depth {
            self.out.push_str("  ");
        }
        self.out.push('<');
        self.out.push_str(tag);
        for (k, v) in attrs {
            self.out.push(' ');
            self.out.push_str(k);
            self.out.push_str("=\"");
            desc_xml::escape_into(&mut self.out, v);
            self.out.push('"');
        }
    }

    fn open(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.start(tag, attrs);
        self.out.push_str(">\n");
        self.depth += 1;
    }

    fn close(&mut self, tag: &str) {
        self.depth = self.depth.saturating_sub(1);
        for _ in 0..self.depth {
            self.out.push_str("  ");
        }
        self.out.push_str("</");
        self.out.push_str(tag);
        self.out.push_str(">\n");
    }

    fn leaf(&mut self, tag: &str, attrs: &[(&str, &str)], text: &str) {
        self.start(tag, attrs);
        self.out.push('>');
        desc_xml::escape_into(&mut self.out, text);
        self.out.push_str("</");
        self.out.push_str(tag);
        self.out.push_str(">\n");
    }

    fn empty(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.start(tag, attrs);
        self.out.push_str("/>\n");
    }
}
