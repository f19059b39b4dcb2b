//! The generated GSDML: current on disk (CI fails on drift), and, parsed back
//! with a real XML parser (roxmltree), consistent with `profinet::model` and
//! drive-core's fault table; every TextId defined once and used.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsStr;
use std::path::PathBuf;

use drive_core::faults::EVENTS;
use profinet::model::{self, DataModule, Direction};
use roxmltree::{Document, Node};

const NS: &str = "http://www.profibus.com/GSDML/2003/11/DeviceProfile";

fn gsdml_dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../gsdml"))
}

/// A GSDML number: "0x…" hexadecimal (Unsigned32hex) or decimal.
fn num(s: &str) -> u64 {
    match s.strip_prefix("0x") {
        Some(h) => u64::from_str_radix(h, 16).unwrap_or_else(|_| panic!("bad hex {s}")),
        None => s.parse().unwrap_or_else(|_| panic!("bad number {s}")),
    }
}

fn attr<'a>(n: Node<'a, '_>, name: &str) -> &'a str {
    n.attribute(name)
        .unwrap_or_else(|| panic!("<{}> has no {name}", n.tag_name().name()))
}

fn child<'a, 'i>(n: Node<'a, 'i>, tag: &str) -> Node<'a, 'i> {
    n.children()
        .find(|c| c.has_tag_name((NS, tag)))
        .unwrap_or_else(|| panic!("<{}> has no <{tag}>", n.tag_name().name()))
}

fn children<'a, 'i>(n: Node<'a, 'i>, tag: &'static str) -> impl Iterator<Item = Node<'a, 'i>> {
    n.children().filter(move |c| c.has_tag_name((NS, tag)))
}

fn descendants<'a, 'i>(n: Node<'a, 'i>, tag: &'static str) -> Vec<Node<'a, 'i>> {
    n.descendants().filter(|c| c.has_tag_name((NS, tag))).collect()
}

fn xml() -> String {
    gsdml::generate().unwrap()
}

fn app<'a, 'i>(doc: &'a Document<'i>) -> Node<'a, 'i> {
    child(child(doc.root_element(), "ProfileBody"), "ApplicationProcess")
}

fn dap<'a, 'i>(doc: &'a Document<'i>) -> Node<'a, 'i> {
    let list: Vec<_> = children(child(app(doc), "DeviceAccessPointList"), "DeviceAccessPointItem").collect();
    assert_eq!(list.len(), 1, "one DAP");
    list[0]
}

/// TextId → Value of the primary language.
fn texts(doc: &Document) -> BTreeMap<String, String> {
    let lang = child(child(app(doc), "ExternalTextList"), "PrimaryLanguage");
    children(lang, "Text")
        .map(|t| (attr(t, "TextId").to_string(), attr(t, "Value").to_string()))
        .collect()
}

/// The text an element's `<Name TextId>` (or `<tag TextId>`) refers to.
fn text_of(doc: &Document, n: Node, tag: &str) -> String {
    texts(doc)[attr(child(n, tag), "TextId")].clone()
}

#[test]
fn gsdml_is_current() {
    let files = gsdml::files().unwrap();
    let check = desc_xml::check_current(
        &gsdml_dir(),
        &files,
        "UPDATE_GSDML",
        "cargo test -p gsdml gsdml_is_current",
    );
    assert_eq!(check, Ok(()));
}

#[test]
fn p025_gsdml_is_well_formed_with_the_gsdml_namespace_and_file_name() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let root = doc.root_element();
    assert!(root.has_tag_name((NS, "ISO15745Profile")));
    let header = child(root, "ProfileHeader");
    assert_eq!(
        child(header, "ProfileIdentification").text(),
        Some("PROFINET Device Profile")
    );
    let name = gsdml::file_name();
    assert_eq!(
        name,
        format!(
            "GSDML-V2.4-OpenServoFirmware-smartServoBL4000-{}.xml",
            gsdml::DATE
        )
    );
    assert_eq!(gsdml::DATE.len(), 8);
    assert!(gsdml::DATE.bytes().all(|b| b.is_ascii_digit()));
    // every ID is unique
    let mut ids = BTreeSet::new();
    for n in root.descendants().filter(|n| n.is_element()) {
        if let Some(id) = n.attribute("ID") {
            assert!(ids.insert(id), "ID {id} twice");
        }
    }
}

#[test]
fn p025_gsdml_identity_is_the_models() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let body = child(doc.root_element(), "ProfileBody");
    let id = child(body, "DeviceIdentity");
    assert_eq!(num(attr(id, "VendorID")), u64::from(model::VENDOR_ID));
    assert_eq!(num(attr(id, "DeviceID")), u64::from(model::DEVICE_ID));
    assert_eq!(attr(child(id, "VendorName"), "Value"), model::VENDOR_NAME);
    let family = child(child(body, "DeviceFunction"), "Family");
    assert_eq!(attr(family, "MainFamily"), "Drives");
    assert_eq!(attr(family, "ProductFamily"), model::STATION_TYPE);
}

#[test]
fn p025_gsdml_has_the_dap_smartservo_bl_4000_in_slot_0() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let dap = dap(&doc);
    let info = child(dap, "ModuleInfo");
    assert_eq!(text_of(&doc, info, "Name"), model::DAP_NAME);
    assert_eq!(text_of(&doc, info, "Name"), "smartServo BL 4000-M/D/C");
    assert_eq!(attr(child(info, "OrderNumber"), "Value"), model::ORDER_NUMBER);
    assert_eq!(
        num(attr(dap, "ModuleIdentNumber")),
        u64::from(model::DAP_MODULE_IDENT)
    );
    assert_eq!(attr(dap, "FixedInSlots"), "0");
    assert_eq!(
        attr(dap, "PhysicalSlots"),
        format!("0..{}", model::DATA_SLOTS.end())
    );
    assert_eq!(attr(dap, "MinDeviceInterval"), "32");
    assert_eq!(
        num(attr(dap, "MinDeviceInterval")),
        u64::from(model::MIN_DEVICE_INTERVAL)
    );
    assert_eq!(attr(dap, "DNS_CompatibleName"), "smartservo-bl-4000");
    assert_eq!(attr(dap, "RequiredSchemaVersion"), "V2.4");
    assert_eq!(attr(child(dap, "CertificationInfo"), "ConformanceClass"), "B");
    // the DAP's subslots: SubslotList, its virtual submodule (subslot 1) and
    // the system-defined interface and ports
    let subslots: Vec<u64> = children(child(dap, "SubslotList"), "SubslotItem")
        .map(|s| num(attr(s, "SubslotNumber")))
        .collect();
    let want: Vec<u64> = model::DAP_SUBSLOTS.iter().map(|&s| u64::from(s)).collect();
    assert_eq!(subslots, want);
    let virt: Vec<_> = children(child(dap, "VirtualSubmoduleList"), "VirtualSubmoduleItem").collect();
    assert_eq!(virt.len(), 1);
    assert_eq!(
        num(attr(virt[0], "SubmoduleIdentNumber")),
        u64::from(model::DAP_SUBMODULE_IDENT)
    );
    // I&M: I&M1…4 writable on subslot 1, no I&M5
    assert_eq!(attr(virt[0], "Writeable_IM_Records"), "1 2 3 4");
    // IM5_Supported belongs to submodules in V2.44, not to the DAP item
    assert!(dap.attribute("IM5_Supported").is_none());
    assert_eq!(num(attr(dap, "MaxSupportedRecordSize")), 4068);
    let sys = child(dap, "SystemDefinedSubmoduleList");
    let ifs: Vec<_> = children(sys, "InterfaceSubmoduleItem").collect();
    assert_eq!(ifs.len(), 1);
    let itf = ifs[0];
    assert_eq!(num(attr(itf, "SubslotNumber")), 0x8000);
    assert_eq!(
        num(attr(itf, "SubmoduleIdentNumber")),
        u64::from(model::INTERFACE_SUBMODULE_IDENT)
    );
    assert_eq!(attr(itf, "SupportedRT_Classes"), "RT_CLASS_1");
    // P-038: conformance class B's SNMP agent is declared next to LLDP
    assert_eq!(attr(itf, "SupportedProtocols"), "SNMP;LLDP");
    let timing = child(child(itf, "ApplicationRelations"), "TimingProperties");
    // P-042: legacy (RTClass 1 IOCRs) and advanced startup (RTClass 2)
    assert_eq!(
        attr(child(itf, "ApplicationRelations"), "StartupMode"),
        "Legacy;Advanced"
    );
    assert_eq!(attr(timing, "SendClock"), "32");
    assert_eq!(attr(timing, "ReductionRatio"), "1 2 4 8 16 32 64 128 256 512");
    // MinDeviceInterval is reachable: send clock × smallest reduction ratio
    assert_eq!(
        u64::from(model::SEND_CLOCK_FACTOR) * u64::from(model::REDUCTION_RATIOS[0]),
        u64::from(model::MIN_DEVICE_INTERVAL)
    );
    let ports: Vec<(u64, u64)> = children(sys, "PortSubmoduleItem")
        .map(|p| {
            (
                num(attr(p, "SubslotNumber")),
                num(attr(p, "SubmoduleIdentNumber")),
            )
        })
        .collect();
    // each port its own ident
    assert_eq!(ports, [(0x8001, 0x8001), (0x8002, 0x8002)]);
    assert_eq!(ports.len(), usize::from(model::PORTS));
}

fn modules<'a, 'i>(doc: &'a Document<'i>) -> Vec<Node<'a, 'i>> {
    children(child(app(doc), "ModuleList"), "ModuleItem").collect()
}

#[test]
fn p026_gsdml_module_idents_are_unique_and_the_models() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let idents: Vec<u64> = modules(&doc)
        .iter()
        .map(|m| num(attr(*m, "ModuleIdentNumber")))
        .collect();
    let unique: BTreeSet<u64> = idents.iter().copied().collect();
    assert_eq!(unique.len(), idents.len(), "ModuleIdentNumbers unique");
    let want: Vec<u64> = DataModule::catalogue().map(|m| u64::from(m.ident())).collect();
    assert_eq!(idents, want);
    assert_eq!(idents.len(), 36);
    assert!(!unique.contains(&u64::from(model::DAP_MODULE_IDENT)));
}

#[test]
fn p026_gsdml_useable_modules_are_every_catalogue_module() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let defined: BTreeSet<&str> = modules(&doc).iter().map(|m| attr(*m, "ID")).collect();
    let refs: Vec<_> = children(child(dap(&doc), "UseableModules"), "ModuleItemRef").collect();
    let targets: BTreeSet<&str> = refs.iter().map(|r| attr(*r, "ModuleItemTarget")).collect();
    assert_eq!(targets.len(), refs.len(), "each module referenced once");
    for t in &targets {
        assert!(defined.contains(t), "ModuleItemTarget {t} has no ModuleItem");
    }
    assert_eq!(targets, defined, "every module is useable");
    let slots = format!("{}..{}", model::DATA_SLOTS.start(), model::DATA_SLOTS.end());
    for r in refs {
        assert_eq!(attr(r, "AllowedInSlots"), slots);
    }
}

#[test]
fn p026_gsdml_in_modules_are_controller_outputs_of_words_x2_bytes() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let t = texts(&doc);
    for (node, m) in modules(&doc).into_iter().zip(DataModule::catalogue()) {
        assert_eq!(attr(node, "ID"), gsdml::module_id(m));
        let name = &t[attr(child(child(node, "ModuleInfo"), "Name"), "TextId")];
        assert_eq!(name, m.name().as_str());
        let subs: Vec<_> = children(child(node, "VirtualSubmoduleList"), "VirtualSubmoduleItem").collect();
        assert_eq!(subs.len(), 1);
        let sub = subs[0];
        assert_eq!(
            num(attr(sub, "SubmoduleIdentNumber")),
            u64::from(model::DATA_SUBMODULE_IDENT)
        );
        let io = child(sub, "IOData");
        // IN module = controller -> drive = the controller's Output
        let (has, lacks) = match m.direction {
            Direction::ToDrive => ("Output", "Input"),
            Direction::FromDrive => ("Input", "Output"),
        };
        assert_eq!(children(io, lacks).count(), 0, "{name}");
        let items: Vec<_> = children(child(io, has), "DataItem").collect();
        let bytes: usize = items
            .iter()
            .map(|i| match attr(*i, "DataType") {
                "Unsigned16" => 2,
                other => panic!("{name}: DataType {other}"),
            })
            .sum();
        assert_eq!(bytes, usize::from(m.words) * 2, "{name}");
        assert_eq!(bytes, m.bytes());
    }
    let names: BTreeSet<String> = DataModule::catalogue()
        .map(|m| m.name().as_str().to_string())
        .collect();
    assert!(names.contains("2 Word Input Data") && names.contains("19 Word Output Data"));
}

#[test]
fn p026_gsdml_io_config_data_fits_one_19_word_module_per_direction() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let io = child(dap(&doc), "IOConfigData");
    // 38 data bytes + IOPS, the other module's IOCS, 4 DAP subslots' IOxS
    let max = 38 + 1 + 1 + model::DAP_SUBSLOTS.len() as u64;
    assert_eq!(num(attr(io, "MaxInputLength")), max);
    assert_eq!(num(attr(io, "MaxOutputLength")), max);
    assert_eq!(gsdml::max_cr_length() as u64, max);
}

#[test]
fn p034_gsdml_channel_diag_items_are_the_fault_table() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let t = texts(&doc);
    let list = child(app(&doc), "ChannelDiagList");
    let items: Vec<_> = children(list, "ChannelDiagItem").collect();
    let faults: Vec<_> = EVENTS.iter().filter(|e| e.code != 0).collect();
    assert_eq!(items.len(), faults.len());
    assert_eq!(items.len(), EVENTS.len() - 1, "all but event 30 Inactive");
    let mut seen = BTreeSet::new();
    for item in items {
        let error_type = num(attr(item, "ErrorType"));
        assert!(seen.insert(error_type), "ErrorType {error_type} twice");
        // 0x1000 + HH, HH the E82 event, added binary (Q-13: 22 -> 0x1016)
        let e = faults
            .iter()
            .find(|e| 0x1000 + u64::from(e.number) == error_type)
            .unwrap_or_else(|| panic!("ErrorType {error_type:#x} is no fault of the table"));
        assert_eq!(
            t[attr(child(item, "Name"), "TextId")],
            format!("E{:02}: {}", e.number, e.name)
        );
        let ext: Vec<u64> = children(child(item, "ExtChannelDiagList"), "ExtChannelDiagItem")
            .map(|x| num(attr(x, "ErrorType")))
            .collect();
        assert_eq!(ext, (0x1000..=0x100F).collect::<Vec<u64>>());
    }
    // the manual's examples keep their numbers: error 54 (following error)
    // -> 0x1036; the example 08-6 -> 0x1008 / 0x1006 by the same rule
    assert!(seen.contains(&0x1036));
    assert_eq!(model::channel_error_type(8), 0x1008);
    assert_eq!(model::ext_channel_error_type(6), Some(0x1006));
}

#[test]
fn p034_gsdml_every_text_id_is_defined_once_and_used() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let lang = child(child(app(&doc), "ExternalTextList"), "PrimaryLanguage");
    let mut defined = BTreeMap::new();
    for t in children(lang, "Text") {
        *defined.entry(attr(t, "TextId")).or_insert(0) += 1;
        assert!(!attr(t, "Value").is_empty(), "{} is empty", attr(t, "TextId"));
    }
    for (id, n) in &defined {
        assert_eq!(*n, 1, "TextId {id} defined {n} times");
    }
    let used: BTreeSet<&str> = doc
        .root_element()
        .descendants()
        .filter(|n| n.is_element() && !n.has_tag_name((NS, "Text")))
        .filter_map(|n| n.attribute("TextId"))
        .collect();
    for id in &used {
        assert!(defined.contains_key(id), "TextId {id} is not defined");
    }
    for id in defined.keys() {
        assert!(used.contains(id), "TextId {id} is defined but not used");
    }
    // ModuleInfo names everywhere, data items and diagnosis included
    assert!(!descendants(doc.root_element(), "DataItem").is_empty());
}

#[test]
fn gsdml_device_bitmap_is_current() {
    let path = gsdml_dir().join(gsdml::bitmap_file_name());
    let want = gsdml::device_bitmap();
    if std::env::var_os("UPDATE_GSDML").is_some() {
        std::fs::write(&path, &want).unwrap();
    }
    let got = std::fs::read(&path).unwrap_or_default();
    assert!(
        got == want,
        "{} is out of date: run UPDATE_GSDML=1 cargo test -p gsdml",
        path.display()
    );
}

#[test]
fn p025_gsdml_device_symbol_is_a_70_by_40_bitmap_beside_the_file() {
    let text = xml();
    let doc = Document::parse(&text).unwrap();
    let graphics: Vec<_> = descendants(app(&doc), "GraphicItem");
    assert_eq!(graphics.len(), 1);
    let id = attr(graphics[0], "ID");
    // GraphicFile names the file without its extension, beside the GSDML
    assert_eq!(
        format!("{}.bmp", attr(graphics[0], "GraphicFile")),
        gsdml::bitmap_file_name()
    );
    let refs = descendants(child(dap(&doc), "Graphics"), "GraphicItemRef");
    assert_eq!(
        refs.iter()
            .map(|r| (attr(*r, "Type"), attr(*r, "GraphicItemTarget")))
            .collect::<Vec<_>>(),
        [("DeviceSymbol", id)]
    );
    let bmp = std::fs::read(gsdml_dir().join(gsdml::bitmap_file_name())).unwrap();
    let u32le = |at: usize| u32::from_le_bytes(bmp[at..at + 4].try_into().unwrap());
    assert_eq!(&bmp[0..2], b"BM");
    assert_eq!(u32le(2) as usize, bmp.len());
    assert_eq!((u32le(18), u32le(22)), (70, 40));
    assert!(bmp.len() < 2048, "keep the symbol tiny: {} bytes", bmp.len());
}

/// PI's schema set: `GSDML_SCHEMA_DIR`, else `../shared/schemas/gsdml` beside
/// the workspace (as CI lays it out).
fn schema() -> Option<PathBuf> {
    let dir = std::env::var_os("GSDML_SCHEMA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| gsdml_dir().join("../../shared/schemas/gsdml"));
    let xsd = dir.join("GSDML-DeviceProfile-v2.44.xsd");
    xsd.is_file().then_some(xsd)
}

/// P-025: the file validates against PI's GSDML schema (V2.44), which TIA
/// Portal applies at import.
#[test]
fn p025_gsdml_file_validates_against_pis_schema() {
    let Some(xsd) = schema() else {
        println!("skipped: no GSDML schema (set GSDML_SCHEMA_DIR or lay ../shared beside the workspace)");
        return;
    };
    xmllint(
        &[OsStr::new("--schema"), xsd.as_os_str()],
        &format!("--schema {}", xsd.display()),
    );
}

#[test]
fn p025_gsdml_file_passes_xmllint() {
    let path = gsdml_dir().join(gsdml::file_name());
    xmllint(&[], &format!("--noout {}", path.display()));
}

/// `xmllint --noout <args> <the GSDML file>` must succeed (`what`: the
/// command as the failure names it); skipped where xmllint does not run.
fn xmllint(args: &[&OsStr], what: &str) {
    let path = gsdml_dir().join(gsdml::file_name());
    match std::process::Command::new("xmllint")
        .arg("--noout")
        .args(args)
        .arg(&path)
        .output()
    {
        Ok(out) => assert!(
            out.status.success(),
            "xmllint {what}: {}",
            String::from_utf8_lossy(&out.stderr)
        ),
        Err(e) => println!("skipped: xmllint not runnable ({e}; Debian package libxml2-utils)"),
    }
}
