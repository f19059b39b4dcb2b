//! The firmware's task bodies (`firmware_tasks::tasks`) against the simulated world
//! (`hil_sim::world`) on the host: the QEMU image's loop without QEMU, so
//! the end-to-end sequence can be debugged with `cargo test`.

use drive_ecat::axis::AxisIo;
use firmware_tasks::clock::Clock;
use firmware_tasks::cycle::{CycleTimer, CYCLE};
use firmware_tasks::net::{NetBuffers, NodeNet, BOARD_NET, EMPTY_SLOTS};
use firmware_tasks::{tasks, Drive, ParamFlash};
use hil_sim::esc::Esc;
use hil_sim::script::Progress;
use hil_sim::world::{new_esc, Event, World};
use nanos::Nanos;
use rtic_core::Exclusive;

struct Board {
    drive: Drive,
    timer: CycleTimer,
    esc: Esc,
    world: World,
    /// The IP stack, polled by the mailbox task (the world's master runs its EoE step).
    net: Option<NodeNet>,
}

impl Board {
    fn new() -> Self {
        Self {
            drive: Drive::new(ParamFlash::new()),
            timer: CycleTimer::new(),
            esc: new_esc(),
            world: World::new(),
            net: None,
        }
    }

    /// With the IP stack on buffers leaked for the test, as the images' statics.
    fn with_net() -> Self {
        let mut b = Self::new();
        b.world = World::with_eoe();
        let bufs = Box::leak(Box::new(NetBuffers::new()));
        let slots = Box::leak(Box::new(EMPTY_SLOTS));
        b.net = Some(NodeNet::new(&mut b.drive, BOARD_NET, bufs, slots, Nanos::ZERO));
        b
    }

    /// Serves the world's next event: a SYNC0 (the ESC's SYNC0 events
    /// taken, the SYNC0 task) and a control cycle (the control task, then
    /// `in_cycle` on the drive and the inputs, then the plant actuated) here;
    /// a frame's time is given back, for the caller's ESC and mailbox tasks.
    fn serve(&mut self, in_cycle: impl FnOnce(&Drive, &[AxisIo; 2])) -> Option<Nanos> {
        let event = self.world.next(self.esc.next_sync0_at(), self.timer.next_at());
        let now = self.world.now();
        match event {
            Event::Sync0 => {
                let _ = self.esc.take_sync0_events(now);
                tasks::sync0(&mut self.drive, &mut self.timer, &mut self.esc.pdi(), now).unwrap();
                None
            }
            Event::Control => {
                let io = self.world.io();
                let cmd = tasks::control(&mut self.drive, &mut self.timer, now, &io);
                in_cycle(&self.drive, &io);
                self.world.actuate(&cmd, CYCLE);
                None
            }
            Event::Frame => Some(now),
        }
    }

    /// Runs events until the script ends; returns its progress log and the
    /// number of control cycles that ran under the PLL.
    fn run(&mut self) -> (Vec<Progress>, u32) {
        let mut log = Vec::new();
        let mut pll_cycles = 0;
        for _ in 0..100_000 {
            if self.world.finished().is_some() {
                break;
            }
            let Some(now) = self.serve(|drive, _| {
                pll_cycles += u32::from(drive.pll().is_some_and(|p| p.is_locked()));
            }) else {
                continue;
            };
            let p = self.world.frame(&mut self.esc);
            tasks::esc_event(&mut self.drive, &mut self.timer, &mut self.esc.pdi(), now).unwrap();
            // the mailbox task runs after the ESC task returns (priority 1)
            match self.net.as_mut() {
                Some(net) => tasks::mailbox_net(&mut self.drive, net, &mut self.esc.pdi(), now).unwrap(),
                None => tasks::mailbox(&mut self.drive, &mut self.esc.pdi(), now).unwrap(),
            }
            tasks::background(&mut Exclusive(&mut self.drive));
            if p != Progress::Busy {
                log.push(p);
            }
        }
        (log, pll_cycles)
    }
}

/// E-107: the control cycle runs on the SYNC0-locked PLL in Op, and the
/// scripted master's whole sequence (Pre-Op SDOs, SYNC0, Op, enable, csp
/// move on both axes, disable, Init) passes through the firmware's tasks.
#[test]
fn e107_task_bodies_run_the_end_to_end_sequence_on_the_pll() {
    let mut b = Board::new();
    let (log, pll_cycles) = b.run();
    assert_eq!(b.world.finished(), Some(true), "{log:?}");
    assert!(log.contains(&Progress::State(8)), "{log:?}");
    assert!(log.contains(&Progress::Enabled), "{log:?}");
    let moved = log.iter().find_map(|p| match p {
        Progress::Moved { position, .. } => Some(*position),
        _ => None,
    });
    let position = moved.expect("move reported");
    assert!((position[0] - (1 << 20)).abs() < 2900, "{position:?}");
    assert!((position[1] + (1 << 20)).abs() < 2900, "{position:?}");
    // the move alone is 200 cycles: they ran with the PLL locked
    assert!(pll_cycles > 200, "{pll_cycles}");
    // every entry of the script's mapping was copied through its slot
    let img = b.drive.pdo_image();
    let slow: Vec<(u16, u8)> = img
        .rx()
        .entries()
        .iter()
        .chain(img.tx().entries())
        .filter(|e| e.slot.is_none())
        .map(|e| (e.index, e.sub))
        .collect();
    assert!(!img.tx().entries().is_empty());
    assert!(slow.is_empty(), "{slow:04X?}");
}

/// E-095/E-096 with the task map: the mailbox task polls the IP stack
/// after each mailbox request (`tasks::mailbox_net`), so the world's master
/// sets the IP, gets the ARP reply with the board's MAC, the ping and the
/// UDP read of A150 in Pre-Op, and the rest of the sequence still runs.
#[test]
fn e095_e096_mailbox_task_runs_the_ip_stack() {
    let mut b = Board::with_net();
    let (log, _) = b.run();
    assert_eq!(b.world.finished(), Some(true), "{log:?}");
    for p in [
        Progress::IpSet,
        Progress::Arp(BOARD_NET.mac),
        Progress::Pinged,
        Progress::UdpRead(1000),
    ] {
        assert!(log.contains(&p), "{p:?} missing: {log:?}");
    }
    assert!(log.contains(&Progress::Enabled), "{log:?}");
    let ip = b.net.as_ref().unwrap().stack().ip();
    assert_eq!(ip, Some((hil_sim::script::eoe::DRIVE_IP, 24)));
}

/// The clock extends a wrapping counter without losing wraps.
#[test]
fn clock_counts_across_counter_wraps() {
    let mut c = Clock::new(144_000_000);
    assert_eq!(c.now(0), Nanos::ZERO);
    assert_eq!(c.now(144_000), Nanos::from_ms(1));
    // five readings three quarters of the counter range apart: past three wraps
    let mut raw = 144_000u32;
    let mut t = Nanos::ZERO;
    for _ in 0..5 {
        raw = raw.wrapping_add(3 << 30);
        t = c.now(raw);
    }
    let ticks = 144_000u64 + 5 * (3u64 << 30);
    assert!(ticks > 3 * (1u64 << 32));
    assert_eq!(t, Nanos::from_ns(ticks * 1_000_000_000 / 144_000_000));
}

/// E-107 free run: without SYNC0 the control cycle runs at A150, the next
/// start counted from the actual start (the PLL following is checked by the
/// end-to-end test above).
#[test]
fn e107_e125_free_run_cycle_at_a150_without_sync0() {
    let mut drive = Drive::new(ParamFlash::new());
    let mut timer = CycleTimer::new();
    assert_eq!(timer.next_at(), CYCLE);
    let io = [drive_ecat::axis::AxisIo::ready(0); 2];
    tasks::control(&mut drive, &mut timer, CYCLE, &io);
    assert_eq!(timer.next_at(), 2 * CYCLE);
    tasks::control(&mut drive, &mut timer, 2 * CYCLE + Nanos::from_ns(10), &io);
    assert_eq!(timer.next_at(), 3 * CYCLE + Nanos::from_ns(10));
    // E-125: the free-running period follows A150 (the axes' dt), 250 µs … 8 ms
    for a150_us in [250, 500, 2000, 4000, 8000] {
        drive
            .objects_mut()
            .set(drive_ecat::parameter_index(0, 150), 0, a150_us)
            .unwrap();
        let now = timer.next_at();
        tasks::control(&mut drive, &mut timer, now, &io);
        assert_eq!(
            timer.next_at(),
            now + Nanos::from_us(a150_us as u64),
            "A150 = {a150_us} µs"
        );
    }
}

/// A save fits the images' parameter flash and loads
/// again after a restart.
#[test]
fn save_fits_the_parameter_flash() {
    let mut drive = Drive::new(ParamFlash::new());
    drive.objects_mut().set(0x6065, 0, 1234).unwrap();
    assert!(drive.save(), "save into {} bytes", 2 * 3072);
    let drive = Drive::new(drive.into_flash().unwrap());
    assert_eq!(drive.startup(), drive_ecat::runtime::Startup::Loaded);
    assert_eq!(drive.objects().get(0x6065, 0), Ok(1234));
}

/// E-018: a save requested over the bus (1010h:01 "save") is not written
/// by the mailbox task but by the background task in idle, and is then in
/// the parameter flash.
#[test]
fn e018_save_is_written_by_the_background_task() {
    use od::Dictionary as _;
    let mut b = Board::new();
    b.drive.objects_mut().set(0x6065, 0, 4321).unwrap();
    let save = drive_ecat::SAVE_SIGNATURE.to_le_bytes();
    b.drive
        .objects_mut()
        .write(0x1010, 1, &save, od::CommState::PreOp)
        .unwrap();
    tasks::mailbox(&mut b.drive, &mut b.esc.pdi(), Nanos::ZERO).unwrap();
    assert!(b.drive.objects().requests().save, "the mailbox task saved");
    tasks::background(&mut Exclusive(&mut b.drive));
    assert!(!b.drive.objects().requests().save);
    let drive = Drive::new(b.drive.into_flash().unwrap());
    assert_eq!(drive.startup(), drive_ecat::runtime::Startup::Loaded);
    assert_eq!(drive.objects().get(0x6065, 0), Ok(4321));
}

/// E-018 with the task map: the background task takes the values and the
/// store out of the drive and writes the flash without holding it. While
/// the job runs the drive keeps cycling, A00[0] reads 1 (running), a second
/// request waits for the store, and the saved set is the one taken at the
/// start.
#[test]
fn e018_save_job_writes_the_flash_outside_the_drive() {
    use od::Dictionary as _;
    const A00: u16 = 0x2000;
    let request = |d: &mut Drive| d.objects_mut().write(A00, 1, &[1], od::CommState::PreOp).unwrap();
    let mut b = Board::new();
    b.drive.objects_mut().set(0x6065, 0, 1234).unwrap();
    request(&mut b.drive);
    let mut job = b.drive.begin_save().expect("a save was requested");
    assert_eq!(b.drive.objects().get(A00, 1), Ok(1), "running");
    assert!(b.drive.flash_mut().is_none(), "the job has the store");
    // the drive runs on meanwhile; a new value and a new request wait
    let io = [drive_ecat::axis::AxisIo::ready(0); 2];
    for k in 1..=3u64 {
        tasks::control(&mut b.drive, &mut b.timer, Nanos::from_ms(k), &io);
    }
    b.drive.objects_mut().set(0x6065, 0, 999).unwrap();
    request(&mut b.drive);
    assert!(b.drive.begin_save().is_none(), "one job at a time");
    job.write();
    assert!(b.drive.end_save(job));
    assert_eq!(
        b.drive.objects().get(A00, 3),
        Ok(drive_ecat::runtime::save_result::OK)
    );
    assert!(
        b.drive.objects().requests().save,
        "the second request is still pending"
    );
    let drive = Drive::new(b.drive.into_flash().unwrap());
    assert_eq!(drive.startup(), drive_ecat::runtime::Startup::Loaded);
    assert_eq!(
        drive.objects().get(0x6065, 0),
        Ok(1234),
        "the values at the start of the job"
    );
}

/// Issue 35, the scope on the firmware's tasks: the recorder the board
/// holds (`tasks::Scope`'s shape, here over a leaked buffer) is configured
/// and armed through its objects as the mailbox task would
/// (`tasks::mailbox_scoped` hands it to the parameter channel), sampled by
/// `tasks::scope` after each control cycle of the scripted move, and read
/// back: axis A's following error and speed set-point over the move, the
/// trigger at the pre-trigger share once the speed set-point passed the level.
#[test]
fn issue35_scope_records_the_move_through_the_task_bodies() {
    use drive_ecat::scope::{Signal, State};
    use od::Dictionary as _;
    let words: &'static mut [u32] = Box::leak(vec![0u32; 2048].into_boxed_slice());
    let mut scope: drive_ecat::scope::Recorder<&'static mut [u32]> = drive_ecat::scope::Recorder::new(words);
    let mut b = Board::new();
    // as the mailbox writes them: the dictionary's checks, then the recorder
    let write = |b: &mut Board, scope: &mut drive_ecat::scope::Recorder<_>, index, sub, v: &[u8]| {
        b.drive
            .objects_mut()
            .with_live(scope)
            .write(index, sub, v, od::CommState::PreOp)
            .unwrap()
    };
    use drive_ecat::params::{T00, T01, T02, T04, T05, T06, T07, T08, T11};
    write(
        &mut b,
        &mut scope,
        T01,
        1,
        &Signal::SpeedSetpoint.code(0).to_le_bytes(),
    );
    write(
        &mut b,
        &mut scope,
        T01,
        2,
        &Signal::FollowingError.code(0).to_le_bytes(),
    );
    write(&mut b, &mut scope, T02, 0, &[2]);
    write(&mut b, &mut scope, T04, 0, &100u32.to_le_bytes());
    write(&mut b, &mut scope, T05, 0, &1u16.to_le_bytes()); // channel 1
    write(&mut b, &mut scope, T06, 0, &[2]); // rising through the level
    write(&mut b, &mut scope, T07, 0, &100_000i32.to_le_bytes());
    write(&mut b, &mut scope, T08, 0, &[25]);
    write(&mut b, &mut scope, T00, 0, &[1]);
    assert_eq!(scope.state(), State::Armed);
    for _ in 0..100_000 {
        if b.world.finished().is_some() || scope.state() == State::Complete {
            break;
        }
        let Some(now) = b.serve(|drive, io| tasks::scope(drive, &mut scope, io)) else {
            continue;
        };
        let _ = b.world.frame(&mut b.esc);
        tasks::esc_event(&mut b.drive, &mut b.timer, &mut b.esc.pdi(), now).unwrap();
        tasks::mailbox_scoped(&mut b.drive, &mut scope, &mut b.esc.pdi(), now).unwrap();
    }
    assert_eq!(
        scope.state(),
        State::Complete,
        "the move's speed set-point passed the level"
    );
    assert_eq!((scope.frames(), scope.trigger_index()), (100, 25));
    let before = scope.value(24, 0).unwrap();
    let at = scope.value(25, 0).unwrap();
    assert!(
        before < 100_000 && at >= 100_000,
        "trigger sample: {before} then {at}"
    );
    let fe_max = (0..100)
        .filter_map(|i| scope.value(i, 1))
        .map(i32::unsigned_abs)
        .max()
        .unwrap();
    assert!(
        fe_max > 0,
        "the following error of the accelerating axis was recorded"
    );
    // the block read the mailbox answers T11 with: sample 0's two channels first
    let mut buf = [0u8; 4096];
    let n = b
        .drive
        .objects_mut()
        .with_live(&mut scope)
        .read(T11, 1, &mut buf, od::CommState::Op)
        .unwrap();
    assert_eq!(n, 100 * 2 * 4, "the whole trace: 100 samples of 2 channels");
    let word = |k: usize| i32::from_le_bytes(buf[4 * k..4 * k + 4].try_into().unwrap());
    assert_eq!(
        (word(0), word(2 * 25 + 1)),
        (scope.value(0, 0).unwrap(), scope.value(25, 1).unwrap())
    );
}
