//! Power cut during an FoE download, at every flash operation it makes.

use super::ethercrab;
use drive_ecat::boot::{Slot, SlotState};
use drive_tests::{fault_row, firmware_file, in_boot, FoeClient, FwNode};
use hil_sim::sim::Simulation;
use std::cell::RefCell;
use std::sync::Arc;

fn node(sim: &RefCell<Simulation<FwNode>>) -> std::cell::RefMut<'_, FwNode> {
    std::cell::RefMut::map(sim.borrow_mut(), |s| &mut s.drives_mut()[0])
}

/// The firmware flash's erase/write operations so far.
fn ops(sim: &RefCell<Simulation<FwNode>>) -> u32 {
    node(sim).slots().flash_mut().0.ops()
}

fn download(sim: &RefCell<Simulation<FwNode>>, file: &[u8]) -> bool {
    in_boot(sim, async |_, sd| {
        FoeClient::new()
            .write_file(&sd, "firmware.efw", file)
            .await
            .is_ok()
    })
}

#[test]
fn e020_power_cut_at_every_flash_operation_of_an_foe_download_keeps_the_image() {
    let row = ethercrab(
        "32",
        "power cut during an FoE download (1 KB image), at each of its flash operations",
        "E-020",
        "at every cut: image A starts confirmed at the next power-on, slot B not pending, a new \
         download is taken and B starts on trial",
    );
    let file = firmware_file(2, 1_000);
    let fresh = || RefCell::new(Simulation::with_nodes(vec![FwNode::factory(20_000)]));
    let sim = fresh();
    let before = ops(&sim);
    assert!(download(&sim, &file), "an uncut download");
    let per_download = ops(&sim) - before;
    assert!(per_download >= 2, "a download erases and writes: {per_download}");
    let mut bad = Vec::new();
    for cut in 0..per_download {
        let sim = fresh();
        Arc::make_mut(&mut node(&sim).slots().flash_mut().0).cut_after(cut);
        let _ = download(&sim, &file);
        Arc::make_mut(&mut node(&sim).slots().flash_mut().0).power_on();
        node(&sim).power_cycle();
        let boot = node(&sim).boot.map(|d| (d.slot, d.trial));
        let b = node(&sim).slots().state(Slot::B).unwrap();
        let again = download(&sim, &file);
        node(&sim).power_cycle();
        let next = node(&sim).boot.map(|d| (d.slot, d.trial));
        let ok = boot == Some((Slot::A, false))
            && !matches!(b, SlotState::Pending { .. })
            && again
            && next == Some((Slot::B, true));
        if !ok {
            bad.push(format!(
                "cut {cut}: boot {boot:?}, B {b:?}, download again {again}, next {next:?}"
            ));
        }
    }
    println!("{per_download} flash operations per download, each cut");
    let seen = if bad.is_empty() {
        "at every cut: image A starts confirmed at the next power-on, slot B not pending, a new download \
         is taken and B starts on trial"
            .to_string()
    } else {
        bad.join("; ")
    };
    fault_row!(row, seen);
}
