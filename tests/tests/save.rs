//! Save values and power loss through the real master (E-018, E-020): written
//! values live in RAM until "save values"; a save cut short by a power loss
//! leaves the previous set intact.

use drive_tests::{line, with_preop, with_sdo};
use hil_sim::sim::Simulation;
use std::cell::RefCell;

/// A258 PDO timeout (ms): a saved UINT16 parameter, writable in every state.
const A258: u16 = drive_ecat::parameter_index(0, 258);
/// A00 Save values: [0] start = sub 1, [2] result = sub 3 (SDO-Info template).
const A00: u16 = drive_ecat::parameter_index(0, 0);
const SAVE: u32 = u32::from_le_bytes(*b"save");

fn read_a258(sim: &RefCell<Simulation>) -> u16 {
    with_preop(sim, async |sd| {
        sd.sdo_read::<u16>(A258, 0).await.expect("read A258")
    })
}

fn write_a258(sim: &RefCell<Simulation>, v: u16, save: Option<(u16, u8, u32)>) {
    with_preop(sim, async |sd| {
        sd.sdo_write(A258, 0, v).await.expect("write A258");
        if let Some((index, sub, value)) = save {
            if index == A00 {
                sd.sdo_write(index, sub, value as u8).await.expect("A00[0] = 1");
            } else {
                sd.sdo_write(index, sub, value).await.expect("1010h:01 = save");
            }
        }
    })
}

fn power_cycle(sim: &RefCell<Simulation>) {
    sim.borrow_mut().drives_mut()[0].power_cycle();
}

#[test]
fn e018_written_values_stay_in_ram_until_saved() {
    let sim = line(1);
    let default = read_a258(&sim);
    write_a258(&sim, default.wrapping_add(7), None);
    assert_eq!(read_a258(&sim), default.wrapping_add(7), "written value in RAM");
    power_cycle(&sim);
    assert_eq!(read_a258(&sim), default, "not saved: lost at power-off");

    // 1010h:01 = "save"
    write_a258(&sim, 1234, Some((0x1010, 1, SAVE)));
    power_cycle(&sim);
    assert_eq!(read_a258(&sim), 1234, "saved through 1010h survives power-off");

    // A00[0] = 1 (Save values), result in A00[2]
    write_a258(&sim, 4321, Some((A00, 1, 1)));
    let result = with_sdo(&sim, async |sd, _| {
        sd.sdo_read::<u8>(A00, 3).await.expect("A00[2]")
    });
    assert_eq!(i64::from(result), drive_ecat::runtime::save_result::OK);
    power_cycle(&sim);
    assert_eq!(read_a258(&sim), 4321, "saved through A00 survives power-off");
}

#[test]
fn e020_power_cut_at_every_step_of_a_save_keeps_a_usable_set() {
    // how many flash operations one save takes
    let sim = line(1);
    write_a258(&sim, 111, Some((0x1010, 1, SAVE)));
    let before = sim.borrow_mut().drives_mut()[0].drive.flash_mut().unwrap().ops();
    write_a258(&sim, 112, Some((0x1010, 1, SAVE)));
    let per_save = sim.borrow_mut().drives_mut()[0].drive.flash_mut().unwrap().ops() - before;
    assert!(per_save >= 2, "a save erases and writes");

    let mut bad = Vec::new();
    for cut in 0..per_save {
        let sim = line(1);
        write_a258(&sim, 500, Some((0x1010, 1, SAVE)));
        // power fails during the next save, after `cut` flash operations
        sim.borrow_mut().drives_mut()[0]
            .drive
            .flash_mut()
            .unwrap()
            .cut_after(cut);
        write_a258(&sim, 600, Some((0x1010, 1, SAVE)));
        sim.borrow_mut().drives_mut()[0]
            .drive
            .flash_mut()
            .unwrap()
            .power_on();
        power_cycle(&sim);
        let startup = sim.borrow().drives()[0].drive.startup();
        let loaded = read_a258(&sim);
        // and the store still works
        write_a258(&sim, 700, Some((0x1010, 1, SAVE)));
        power_cycle(&sim);
        let again = read_a258(&sim);
        if (startup, loaded, again) != (drive_ecat::runtime::Startup::Loaded, 500, 700) {
            bad.push(format!(
                "cut after {cut} of {per_save} operations: {startup:?}, A258 {loaded}, saved again {again}"
            ));
        }
    }
    let seen = if bad.is_empty() {
        "at every cut: the previous set loads at the next power-on (A258 = 500), and a save works again"
            .to_string()
    } else {
        bad.join("; ")
    };
    let row = drive_tests::matrix::Row {
        order: "31",
        case: "power cut during a parameter save (1010h:01), at each of its flash operations",
        spec: "E-020",
        peer: "ethercrab",
        expected: "at every cut: the previous set loads at the next power-on (A258 = 500), and a save works \
                   again",
    };
    drive_tests::fault_row!(row, seen);
}

/// A09 restart (E-019, E-140, E-145): the answer to the request comes
/// first; 100 ms later the device restarts as after a power cycle: the ESC
/// is back in Init, the saved values are in force (a value written after
/// the save is gone), the diagnosis history is empty; a request in the
/// first 100 ms does not restart it yet.
#[test]
fn e019_e140_e145_a09_restart_starts_again_with_the_saved_values() {
    use drive_tests::al_status;
    const A09: u16 = drive_ecat::parameter_index(0, 9);
    let sim = line(1);
    let before = with_sdo(&sim, async |sd, _| {
        sd.sdo_write(A258, 0, 777u16).await.unwrap();
        sd.sdo_write(0x1010, 1, SAVE).await.unwrap();
        sd.sdo_write(A258, 0, 888u16).await.unwrap();
        // a refused state change: a message in the history
        drive_tests::request(sd, drive_tests::al::BOOT).await;
        let history: u8 = sd.sdo_read(0x10F3, 2).await.unwrap();
        sd.sdo_write(A09, 1, 1u8).await.expect("A09[0] = 1 answered");
        // within the delay: still the same device
        let t = sim.borrow().now().as_ns();
        sim.borrow_mut().advance_to(nanos::Nanos::from_ns(t + 50_000_000));
        let still = sd.sdo_read::<u16>(A258, 0).await.unwrap();
        (history, still, al_status(sd).await)
    });
    assert_ne!(before.0, 0, "a message in the history before the restart");
    assert_eq!(before.1, 888, "no restart within 100 ms");
    assert_eq!(before.2 .0 & 0x0F, drive_tests::al::PREOP);
    let t = sim.borrow().now().as_ns();
    sim.borrow_mut()
        .advance_to(nanos::Nanos::from_ns(t + 100_000_000));
    {
        let s = sim.borrow();
        let d = &s.drives()[0];
        assert_eq!(d.drive.slave().state(), esc::AlState::Init, "restarted: Init");
        assert_eq!(
            d.drive.startup(),
            drive_ecat::runtime::Startup::Loaded,
            "the saved set"
        );
    }
    let after = with_sdo(&sim, async |sd, _| {
        let a258: u16 = sd.sdo_read(A258, 0).await.unwrap();
        let history: u8 = sd.sdo_read(0x10F3, 2).await.unwrap();
        let restart: u8 = sd.sdo_read(A09, 1).await.unwrap();
        (a258, history, restart)
    });
    assert_eq!(after, (777, 0, 0), "saved A258, empty history, A09[0] back to 0");
}
