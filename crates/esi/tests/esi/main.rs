//! The generated ESI files: current on disk (CI fails on drift), and, parsed
//! back with a real XML parser (roxmltree), consistent with the SII image
//! and the object dictionary of each subindex template.
//!
//! Here: the XML helpers and the ESI texts the modules share; the tests, by what they compare the
//! ESI with, in the modules.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;

use drive_ecat::{revision, Template, Variant};
use ecat::sii::{categories, find_category, records, sii_string, sii_word};
use esc::sii::{category, word};
use od::{CommState, DataType, Dictionary};
use roxmltree::{Document, Node};

mod dictionary;
mod files;
mod modules;
mod sii;

fn esi_dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../esi"))
}

/// A "#x…" hexadecimal or decimal number (ETG.2000 HexDecValue).
fn num(s: &str) -> u64 {
    let s = s.trim();
    match s.strip_prefix("#x") {
        Some(h) => u64::from_str_radix(h, 16).unwrap_or_else(|_| panic!("bad hex {s}")),
        None => s.parse().unwrap_or_else(|_| panic!("bad number {s}")),
    }
}

fn hex_bytes(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

fn child<'a, 'i>(n: Node<'a, 'i>, tag: &str) -> Node<'a, 'i> {
    n.children()
        .find(|c| c.has_tag_name(tag))
        .unwrap_or_else(|| panic!("<{}> has no <{tag}>", n.tag_name().name()))
}

fn opt_child<'a, 'i>(n: Node<'a, 'i>, tag: &str) -> Option<Node<'a, 'i>> {
    n.children().find(|c| c.has_tag_name(tag))
}

fn children<'a, 'i>(n: Node<'a, 'i>, tag: &'static str) -> impl Iterator<Item = Node<'a, 'i>> {
    n.children().filter(move |c| c.has_tag_name(tag))
}

fn text<'a>(n: Node<'a, '_>, tag: &str) -> &'a str {
    child(n, tag).text().unwrap_or("")
}

fn device_node<'a, 'i>(doc: &'a Document<'i>) -> Node<'a, 'i> {
    child(
        child(child(doc.root_element(), "Descriptions"), "Devices"),
        "Device",
    )
}

/// The `<Modules>` of the file (E-149).
fn modules<'a, 'i>(doc: &'a Document<'i>) -> Vec<Node<'a, 'i>> {
    children(
        child(child(doc.root_element(), "Descriptions"), "Modules"),
        "Module",
    )
    .collect()
}

/// The ident of a `<Module>`.
fn module_ident(m: Node) -> u32 {
    num(child(m, "Type").attribute("ModuleIdent").unwrap()) as u32
}

/// The `<Slot>`s of the device.
fn slots<'a, 'i>(dev: Node<'a, 'i>) -> Vec<Node<'a, 'i>> {
    children(child(dev, "Slots"), "Slot").collect()
}

/// A PDO's entries as mapping values (index << 16 | sub << 8 | bit length).
fn mapped(pdo: Node) -> Vec<u32> {
    children(pdo, "Entry")
        .map(|e| {
            (num(text(e, "Index")) << 16 | num(text(e, "SubIndex")) << 8 | num(text(e, "BitLen"))) as u32
        })
        .collect()
}

/// The ESI text of `variant` in `template`, as generated (the drift test
/// keeps the files equal).
fn esi(variant: Variant, template: Template) -> String {
    esi::generate(variant, template).unwrap()
}

/// Every (device, template) pair with an ESI.
fn each() -> Vec<(Variant, Template)> {
    esi::VARIANTS
        .iter()
        .flat_map(|&v| esi::TEMPLATES.iter().map(move |&t| (v, t)))
        .collect()
}

fn data_type<'a, 'i>(profile: Node<'a, 'i>, name: &str) -> Node<'a, 'i> {
    children(child(child(profile, "Dictionary"), "DataTypes"), "DataType")
        .find(|d| text(*d, "Name") == name)
        .unwrap_or_else(|| panic!("no DataType {name}"))
}

fn object<'a, 'i>(profile: Node<'a, 'i>, index: u16) -> Node<'a, 'i> {
    children(child(child(profile, "Dictionary"), "Objects"), "Object")
        .find(|o| num(text(*o, "Index")) == u64::from(index))
        .unwrap_or_else(|| panic!("no Object {index:04X}h"))
}

/// The numeric defaults of object `index` in the ESI dictionary, in entry order.
fn defaults_of(profile: Node, index: u16) -> Vec<u64> {
    let info = child(object(profile, index), "Info");
    children(info, "SubItem")
        .map(|s| {
            let data = hex_bytes(text(child(s, "Info"), "DefaultData"));
            data.iter().rev().fold(0u64, |v, b| v << 8 | u64::from(*b))
        })
        .collect()
}
