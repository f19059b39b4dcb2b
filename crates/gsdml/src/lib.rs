//! The drive's GSDML (PROFINET General Station Description, schema V2.4),
//! generated from the one declaration: [`profinet::model`] (identity, the DAP
//! "smartServo BL 4000-M/D/C" with its subslots, the 36 IN/OUT modules of
//! 2…19 words, timing, I&M, the diagnosis numbering) and drive-core's fault
//! table [`drive_core::faults::EVENTS`] (the `ChannelDiagList` texts). Nothing
//! in the file is typed twice: change the declaration and the drift check
//! `gsdml_is_current` fails until the file is regenerated
//! (`UPDATE_GSDML=1 cargo test -p gsdml gsdml_is_current`, or
//! `cargo run -p gsdml`).
//!
//! Decisions written into the file (spec `profidrive.md` §2.6–§2.8):
//!
//! - Module directions from the **controller's** view, as GSDML counts them:
//!   an "IN module" (controller → drive, the receive telegram) has
//!   `<IOData><Output>`, an "OUT module" (drive → controller, the response
//!   telegram) has `<IOData><Input>`. The catalogue names stay the manual's
//!   (drive's view, E-18).
//! - Data items: N × `Unsigned16` named "Word 1" … "Word N", not one
//!   `OctetString`: the telegram is a sequence of 16-bit big-endian words
//!   (spec §4.2), and what each word carries is configured in the drive, so
//!   the file can name them by position only; every engineering tool knows
//!   `Unsigned16`, and the PLC sees word addresses as in the manual's example.
//!   One consistency unit per module ("All items consistency").
//! - One module per direction in slots [`model::DATA_SLOTS`] (1 and 2, either
//!   order); `IOConfigData` allows one 19-word module per CR
//!   ([`max_cr_length`]).
//! - Timing: `MinDeviceInterval` [`model::MIN_DEVICE_INTERVAL`] = 32 (1 ms),
//!   send clock 32, reduction ratios 1…512; RT_CLASS_1 frames only, CC-B,
//!   startup modes "Legacy;Advanced" (IOCRs of RTClass 1 or 2).
//! - `MaxSupportedRecordSize` [`model::MAX_RECORD_SIZE`] (4,068, the schema's
//!   minimum); each port submodule has its own ident
//!   ([`model::port_submodule_ident`]); the catalogue's device symbol is the
//!   bitmap [`bitmap_file_name`] beside the file ([`device_bitmap`]).
//! - Diagnosis: one `ChannelDiagItem` per drive fault (main error HH = its
//!   E82 event, ErrorType [`model::channel_error_type`]), each with an
//!   `ExtChannelDiagList` of the sub errors S = 0…15 (its E43 cause,
//!   [`model::ext_channel_error_type`]).
//!
//! A host tool: it uses `std` (`String`, `BTreeMap`).

mod bitmap;
mod xml;

pub use bitmap::device_bitmap;

use std::collections::BTreeMap;
use std::fmt;

use drive_core::faults::{EventInfo, EVENTS};
use profinet::model::{self, DataModule, Direction};
use xml::Xml;

/// Release date in the file name, fixed so that the file is reproducible;
/// change it with a change a controller's user should notice.
pub const DATE: &str = "20261201";
/// The GSDML schema version the file is written to (file name, `PNIO_Version`,
/// `RequiredSchemaVersion`).
pub const SCHEMA_VERSION: &str = "V2.4";
/// The family in the hardware catalogue (`DeviceFunction/Family`).
pub const MAIN_FAMILY: &str = "Drives";
/// MAU type of the ports: 16 = 100BASE-TX full duplex (spec §2.2).
pub const MAU_TYPE: u16 = 16;

/// Why the GSDML could not be generated (both are generator bugs).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Error {
    /// One TextId was given two different texts.
    TextConflict(String),
    /// The XML elements do not balance.
    Unbalanced,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::TextConflict(id) => write!(f, "TextId {id} has two different texts"),
            Error::Unbalanced => f.write_str("unbalanced XML elements"),
        }
    }
}

impl std::error::Error for Error {}

/// `s` without anything but ASCII letters and digits (a file-name token).
fn token(s: &str) -> String {
    s.chars().filter(char::is_ascii_alphanumeric).collect()
}

/// The file name, `GSDML-V2.4-<vendor>-<family>-<date>.xml`: vendor
/// [`model::VENDOR_NAME`], family [`model::STATION_TYPE`] (letters and digits
/// only), date [`DATE`].
pub fn file_name() -> String {
    format!(
        "GSDML-{SCHEMA_VERSION}-{}-{}-{DATE}.xml",
        token(model::VENDOR_NAME),
        token(model::STATION_TYPE)
    )
}

/// The station name the engineering tool proposes (`DNS_CompatibleName`):
/// [`model::STATION_TYPE`] in lower case, every run of other characters one
/// `-`.
pub fn dns_compatible_name() -> String {
    let mut out = String::new();
    for c in model::STATION_TYPE.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.is_empty() && !out.ends_with('-') {
            out.push('-');
        }
    }
    out.trim_end_matches('-').to_string()
}

fn kind(m: DataModule) -> &'static str {
    match m.direction {
        Direction::ToDrive => "IN",
        Direction::FromDrive => "OUT",
    }
}

/// The GSDML `ID` of a catalogue module, e.g. `M_OUT_18`.
pub fn module_id(m: DataModule) -> String {
    format!("M_{}_{:02}", kind(m), m.words)
}

/// The GSDML `ID` of a catalogue module's (only) submodule, e.g. `S_OUT_18`.
pub fn submodule_id(m: DataModule) -> String {
    format!("S_{}_{:02}", kind(m), m.words)
}

/// `IOConfigData` `MaxInputLength` = `MaxOutputLength`: the longest C-SDU of
/// either CR, counted as the controller does: the largest module of that
/// direction (19 words) and its IOPS, the IOCS of the other direction's
/// module, and one IOxS for each dataless DAP subslot (their IOPS in the
/// input CR, their IOCS in the output CR).
pub fn max_cr_length() -> usize {
    let data = usize::from(*model::MODULE_WORDS.end()) * 2;
    data + 1 + 1 + model::DAP_SUBSLOTS.len()
}

/// The drive's main errors with a `ChannelDiagItem`: every event of
/// [`EVENTS`] that is a fault (not event 30 "Inactive", error code 0000h),
/// by event number.
pub fn main_errors() -> Vec<&'static EventInfo> {
    let mut v: Vec<_> = EVENTS.iter().filter(|e| e.code != 0).collect();
    v.sort_by_key(|e| e.number);
    v
}

/// The name of main error `e` in the controller's diagnosis, e.g.
/// "E54: Following error" (the manual's style, spec §2.7).
pub fn main_error_text(e: &EventInfo) -> String {
    format!("E{:02}: {}", e.number, e.name)
}

/// The name of sub error `sub` in the controller's diagnosis.
pub fn sub_error_text(sub: u8) -> String {
    format!("Cause {sub}")
}

/// The external texts: each TextId defined once, kept sorted.
#[derive(Default)]
struct Texts(BTreeMap<String, String>);

impl Texts {
    /// Defines (or re-uses) TextId `id` with `value`; returns the id.
    fn def(&mut self, id: impl Into<String>, value: impl Into<String>) -> Result<String, Error> {
        let (id, value) = (id.into(), value.into());
        match self.0.get(&id) {
            Some(v) if *v != value => Err(Error::TextConflict(id)),
            Some(_) => Ok(id),
            None => {
                self.0.insert(id.clone(), value);
                Ok(id)
            }
        }
    }
}

/// The GSDML document.
pub fn generate() -> Result<String, Error> {
    let mut x = Xml::new();
    let mut t = Texts::default();
    x.open(
        "ISO15745Profile",
        &[
            ("xmlns", "http://www.profibus.com/GSDML/2003/11/DeviceProfile"),
            ("xmlns:xsi", "http://www.w3.org/2001/XMLSchema-instance"),
            (
                "xsi:schemaLocation",
                "http://www.profibus.com/GSDML/2003/11/DeviceProfile ..\\xsd\\GSDML-DeviceProfile-V2.4.xsd",
            ),
        ],
    );
    profile_header(&mut x);
    x.open("ProfileBody", &[]);
    device_identity(&mut x, &mut t)?;
    x.open("ApplicationProcess", &[]);
    x.open("DeviceAccessPointList", &[]);
    dap(&mut x, &mut t)?;
    x.close();
    module_list(&mut x, &mut t)?;
    channel_diag_list(&mut x, &mut t)?;
    x.open("GraphicsList", &[]);
    let graphic = bitmap_stem();
    x.empty("GraphicItem", &[("ID", GRAPHIC_ID), ("GraphicFile", &graphic)]);
    x.close();
    x.open("ExternalTextList", &[]);
    x.open("PrimaryLanguage", &[]);
    for (id, value) in &t.0 {
        x.empty("Text", &[("TextId", id), ("Value", value)]);
    }
    x.close();
    x.close();
    x.close(); // ApplicationProcess
    x.close(); // ProfileBody
    x.close(); // ISO15745Profile
    x.finish().ok_or(Error::Unbalanced)
}

/// The `ID` of the device symbol's `GraphicItem`.
const GRAPHIC_ID: &str = "G_DeviceSymbol";

/// The device symbol's file name without extension (the GSDML's
/// `GraphicFile`), by PI's convention `GSDML-<vendor ID>-<device ID>-<name>`.
pub fn bitmap_stem() -> String {
    format!(
        "GSDML-{:04X}-{:04X}-{}",
        model::VENDOR_ID,
        model::DEVICE_ID,
        token(model::STATION_TYPE)
    )
}

/// The device symbol's file name, [`bitmap_stem`]`.bmp`.
pub fn bitmap_file_name() -> String {
    format!("{}.bmp", bitmap_stem())
}

/// Every generated file under `gsdml/`: (file name, contents).
pub fn files() -> Result<Vec<(String, String)>, Error> {
    Ok(vec![(file_name(), generate()?)])
}

/// The ISO 15745 profile header, fixed for every PROFINET GSDML.
fn profile_header(x: &mut Xml) {
    x.open("ProfileHeader", &[]);
    x.text("ProfileIdentification", "PROFINET Device Profile");
    x.text("ProfileRevision", "1.00");
    x.text("ProfileName", "Device Profile for PROFINET Devices");
    x.text("ProfileSource", "PROFIBUS Nutzerorganisation e. V. (PNO)");
    x.text("ProfileClassID", "Device");
    x.open("ISO15745Reference", &[]);
    x.text("ISO15745Part", "4");
    x.text("ISO15745Edition", "1");
    x.text("ProfileTechnology", "GSDML");
    x.close();
    x.close();
}

fn device_identity(x: &mut Xml, t: &mut Texts) -> Result<(), Error> {
    let vendor = format!("0x{:04X}", model::VENDOR_ID);
    let device = format!("0x{:04X}", model::DEVICE_ID);
    x.open("DeviceIdentity", &[("VendorID", &vendor), ("DeviceID", &device)]);
    let info = t.def(
        "T_DeviceInfo",
        format!(
            "{} servo drive: PROFINET IO device, conformance class B, RT_CLASS_1, \
             PROFIdrive-style profile",
            model::STATION_TYPE
        ),
    )?;
    x.empty("InfoText", &[("TextId", &info)]);
    x.empty("VendorName", &[("Value", model::VENDOR_NAME)]);
    x.close();
    x.open("DeviceFunction", &[]);
    x.empty(
        "Family",
        &[
            ("MainFamily", MAIN_FAMILY),
            ("ProductFamily", model::STATION_TYPE),
        ],
    );
    x.close();
    Ok(())
}

/// The TextId of a DAP subslot's name (subslot 1, the interface, a port).
fn subslot_text(t: &mut Texts, subslot: u16) -> Result<String, Error> {
    match subslot {
        0x8000 => t.def("T_Interface", "Interface X1"),
        0x8001..=0x80FF => {
            let port = subslot - 0x8000;
            t.def(format!("T_Port_{port}"), format!("Port {port} (RTE{})", port - 1))
        }
        _ => t.def(format!("T_Subslot_{subslot}"), model::STATION_TYPE),
    }
}

fn dap(x: &mut Xml, t: &mut Texts) -> Result<(), Error> {
    let slots = &model::DATA_SLOTS;
    let physical = format!("0..{}", slots.end());
    let ident = format!("0x{:08X}", model::DAP_MODULE_IDENT);
    let mdi = model::MIN_DEVICE_INTERVAL.to_string();
    let dns = dns_compatible_name();
    let record_size = model::MAX_RECORD_SIZE.to_string();
    x.open(
        "DeviceAccessPointItem",
        &[
            ("ID", "DAP_1"),
            ("PNIO_Version", SCHEMA_VERSION),
            ("PhysicalSlots", &physical),
            ("ModuleIdentNumber", &ident),
            ("MinDeviceInterval", &mdi),
            ("DNS_CompatibleName", &dns),
            ("FixedInSlots", "0"),
            ("ObjectUUID_LocalIndex", "1"),
            ("RequiredSchemaVersion", SCHEMA_VERSION),
            ("MultipleWriteSupported", "true"),
            ("DeviceAccessSupported", "false"),
            ("CheckDeviceID_Allowed", "true"),
            ("NameOfStationNotTransferable", "false"),
            ("LLDP_NoD_Supported", "true"),
            ("ResetToFactoryModes", "2"),
            ("AddressAssignment", "DCP"),
            ("MaxSupportedRecordSize", &record_size),
        ],
    );
    let name = t.def("T_DAP_Name", model::DAP_NAME)?;
    let info = t.def(
        "T_DAP_Info",
        format!(
            "{}: interface X1 with {} ports; one IN module (controller -> drive, receive \
             telegram) and one OUT module (drive -> controller, response telegram) of {} to {} \
             words in slots {} and {}",
            model::DAP_NAME,
            model::PORTS,
            model::MODULE_WORDS.start(),
            model::MODULE_WORDS.end(),
            slots.start(),
            slots.end()
        ),
    )?;
    x.open("ModuleInfo", &[]);
    x.empty("Name", &[("TextId", &name)]);
    x.empty("InfoText", &[("TextId", &info)]);
    x.empty("VendorName", &[("Value", model::VENDOR_NAME)]);
    x.empty("OrderNumber", &[("Value", model::ORDER_NUMBER)]);
    x.empty("SoftwareRelease", &[("Value", model::SOFTWARE_RELEASE)]);
    x.close();
    x.empty(
        "CertificationInfo",
        &[("ConformanceClass", "B"), ("NetloadClass", "I")],
    );
    x.open("SubslotList", &[]);
    for subslot in model::DAP_SUBSLOTS {
        let id = subslot_text(t, subslot)?;
        let number = subslot.to_string();
        x.empty("SubslotItem", &[("SubslotNumber", &number), ("TextId", &id)]);
    }
    x.close();
    let max = max_cr_length().to_string();
    x.empty(
        "IOConfigData",
        &[("MaxInputLength", &max), ("MaxOutputLength", &max)],
    );
    x.open("UseableModules", &[]);
    let allowed = format!("{}..{}", slots.start(), slots.end());
    for m in DataModule::catalogue() {
        let target = module_id(m);
        x.empty(
            "ModuleItemRef",
            &[("ModuleItemTarget", &target), ("AllowedInSlots", &allowed)],
        );
    }
    x.close();
    x.open("VirtualSubmoduleList", &[]);
    let sub_ident = format!("0x{:08X}", model::DAP_SUBMODULE_IDENT);
    let im: Vec<String> = model::WRITEABLE_IM_RECORDS.iter().map(u8::to_string).collect();
    let im = im.join(" ");
    x.open(
        "VirtualSubmoduleItem",
        &[
            ("ID", "DAP_1_S1"),
            ("SubmoduleIdentNumber", &sub_ident),
            ("Writeable_IM_Records", &im),
            ("MayIssueProcessAlarm", "false"),
        ],
    );
    x.empty("IOData", &[]);
    x.open("ModuleInfo", &[]);
    x.empty("Name", &[("TextId", &name)]);
    x.empty("InfoText", &[("TextId", &info)]);
    x.close();
    x.close();
    x.close();
    system_defined_submodules(x, t)?;
    x.open("Graphics", &[]);
    x.empty(
        "GraphicItemRef",
        &[("Type", "DeviceSymbol"), ("GraphicItemTarget", GRAPHIC_ID)],
    );
    x.close();
    x.close();
    Ok(())
}

fn system_defined_submodules(x: &mut Xml, t: &mut Texts) -> Result<(), Error> {
    x.open("SystemDefinedSubmoduleList", &[]);
    let ident = format!("0x{:08X}", model::INTERFACE_SUBMODULE_IDENT);
    let text = subslot_text(t, 0x8000)?;
    x.open(
        "InterfaceSubmoduleItem",
        &[
            ("ID", "DAP_1_IF"),
            ("SubmoduleIdentNumber", &ident),
            ("SubslotNumber", "32768"),
            ("TextId", &text),
            ("SupportedRT_Classes", "RT_CLASS_1"),
            // the SNMP agent on UDP 161 (P-038, crates/snmp) and LLDP; no PTP/IRT
            ("SupportedProtocols", "SNMP;LLDP"),
        ],
    );
    x.open("ApplicationRelations", &[("StartupMode", "Legacy;Advanced")]);
    let clock = model::SEND_CLOCK_FACTOR.to_string();
    let ratios: Vec<String> = model::REDUCTION_RATIOS.iter().map(u16::to_string).collect();
    let ratios = ratios.join(" ");
    x.empty(
        "TimingProperties",
        &[("SendClock", &clock), ("ReductionRatio", &ratios)],
    );
    x.close();
    x.close();
    for port in 1..=model::PORTS {
        let subslot = 0x8000 + port;
        let id = format!("DAP_1_P{port}");
        let ident = format!("0x{:08X}", model::port_submodule_ident(port));
        let number = subslot.to_string();
        let text = subslot_text(t, subslot)?;
        x.open(
            "PortSubmoduleItem",
            &[
                ("ID", &id),
                ("SubmoduleIdentNumber", &ident),
                ("SubslotNumber", &number),
                ("TextId", &text),
            ],
        );
        x.open("MAUTypeList", &[]);
        x.empty("MAUTypeItem", &[("Value", &MAU_TYPE.to_string())]);
        x.close();
        x.close();
    }
    x.close();
    Ok(())
}

fn module_list(x: &mut Xml, t: &mut Texts) -> Result<(), Error> {
    x.open("ModuleList", &[]);
    for m in DataModule::catalogue() {
        let id = module_id(m);
        let ident = format!("0x{:08X}", m.ident());
        x.open("ModuleItem", &[("ID", &id), ("ModuleIdentNumber", &ident)]);
        let name = t.def(format!("T_{id}_Name"), m.name().as_str())?;
        let (what, telegram, arrow, cr) = match m.direction {
            Direction::ToDrive => ("IN", "receive", "controller -> drive", "output"),
            Direction::FromDrive => ("OUT", "response", "drive -> controller", "input"),
        };
        let info = t.def(
            format!("T_{id}_Info"),
            format!(
                "{what} module: {telegram} telegram of {} words ({} bytes), {arrow} \
                 (controller {cr} data)",
                m.words,
                m.bytes()
            ),
        )?;
        x.open("ModuleInfo", &[]);
        x.empty("Name", &[("TextId", &name)]);
        x.empty("InfoText", &[("TextId", &info)]);
        x.close();
        x.open("VirtualSubmoduleList", &[]);
        let sub = submodule_id(m);
        let sub_ident = format!("0x{:08X}", model::DATA_SUBMODULE_IDENT);
        x.open(
            "VirtualSubmoduleItem",
            &[
                ("ID", &sub),
                ("SubmoduleIdentNumber", &sub_ident),
                ("MayIssueProcessAlarm", "false"),
            ],
        );
        x.open("IOData", &[]);
        // the controller's view: controller -> drive is its Output
        let dir = match m.direction {
            Direction::ToDrive => "Output",
            Direction::FromDrive => "Input",
        };
        x.open(dir, &[("Consistency", "All items consistency")]);
        for word in 1..=m.words {
            let text = t.def(format!("T_Word_{word:02}"), format!("Word {word}"))?;
            x.empty("DataItem", &[("DataType", "Unsigned16"), ("TextId", &text)]);
        }
        x.close();
        x.close();
        x.open("ModuleInfo", &[]);
        x.empty("Name", &[("TextId", &name)]);
        x.empty("InfoText", &[("TextId", &info)]);
        x.close();
        x.close();
        x.close();
        x.close();
    }
    x.close();
    Ok(())
}

fn channel_diag_list(x: &mut Xml, t: &mut Texts) -> Result<(), Error> {
    x.open("ChannelDiagList", &[]);
    for e in main_errors() {
        let error_type = model::channel_error_type(e.number).to_string();
        x.open("ChannelDiagItem", &[("ErrorType", &error_type)]);
        let name = t.def(format!("T_Diag_{:02}", e.number), main_error_text(e))?;
        x.empty("Name", &[("TextId", &name)]);
        x.open("ExtChannelDiagList", &[]);
        for sub in model::SUB_ERRORS {
            let Some(ext) = model::ext_channel_error_type(sub) else {
                continue;
            };
            let ext = ext.to_string();
            x.open("ExtChannelDiagItem", &[("ErrorType", &ext)]);
            let name = t.def(format!("T_Cause_{sub:02}"), sub_error_text(sub))?;
            x.empty("Name", &[("TextId", &name)]);
            x.close();
        }
        x.close();
        x.close();
    }
    x.close();
    Ok(())
}
