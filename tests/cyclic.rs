//! Cyclic process data of one drive in Op: the standard PDO layout ([`Cyclic`], `motion/`) and
//! remapped layouts as raw bytes ([`RawCyclic`], `motion_more.rs`).

use crate::{axis, REV};
use ethercrab::{MainDevice, SubDeviceRef};
use hil_sim::sim::Simulation;
use nanos::Nanos;
use std::cell::RefCell;

/// A SubDevice of an [`OpGroup`].
pub type OpSubDevice<'a> = SubDeviceRef<'a, ethercrab::SubDevicePdi<'a, 512, ethercrab::DefaultLock>>;

/// A group in Op as [`init`](crate::init) + `into_op` leave it.
pub type OpGroup = ethercrab::SubDeviceGroup<
    8,
    512,
    ethercrab::DefaultLock,
    ethercrab::subdevice_group::Op,
    ethercrab::subdevice_group::NoDc,
>;

/// One master cycle of the simulated line (the drive's A150 default).
pub const MASTER_CYCLE: Nanos = hil_sim::sim::CONTROL_CYCLE;

/// Standard RxPDO length (C-130): 6040h, 6060h, 607Ah, 60FFh, 60B1h, 60B2h, 6071h, 60FEh:01.
pub const RXPDO_LEN: usize = 23;
/// Standard TxPDO length (C-131).
pub const TXPDO_LEN: usize = 29;

/// The standard TxPDO of axis A as the master received it (C-131 offsets).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TxPdo {
    /// 6041h statusword @0.
    pub statusword: u16,
    /// 6061h modes of operation display @2.
    pub mode_display: i8,
    /// 6064h position actual value @3, inc.
    pub position: i32,
    /// 606Ch velocity actual value @7, inc/s.
    pub velocity: i32,
    /// 6077h torque actual value @11, 0.1 % of 6076h.
    pub torque: i16,
    /// 60F4h following error actual value @13, inc.
    pub following_error: i32,
    /// 60FDh digital inputs @17.
    pub digital_inputs: u32,
    /// 60E4h:01 additional position actual value @21, inc.
    pub additional_position: i32,
    /// E201 @25.
    pub e201: u16,
    /// A67 user statusword @27.
    pub a67: u16,
}

impl TxPdo {
    /// Decodes the 29-byte standard TxPDO.
    pub fn decode(b: &[u8]) -> Self {
        assert_eq!(b.len(), TXPDO_LEN, "standard TxPDO length");
        let u16_ = |o: usize| u16::from_le_bytes([b[o], b[o + 1]]);
        let i32_ = |o: usize| i32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
        Self {
            statusword: u16_(0),
            mode_display: b[2] as i8,
            position: i32_(3),
            velocity: i32_(7),
            torque: u16_(11) as i16,
            following_error: i32_(13),
            digital_inputs: i32_(17) as u32,
            additional_position: i32_(21),
            e201: u16_(25),
            a67: u16_(27),
        }
    }

    /// Statusword bits 0–6 with the CiA 402 state mask 0x6F (bit 4 voltage
    /// enabled is not part of the state).
    pub fn state(&self) -> u16 {
        self.statusword & 0x6F
    }

    /// Statusword bit `n`.
    pub fn bit(&self, n: u8) -> bool {
        self.statusword & (1 << n) != 0
    }
}

/// Statusword patterns (& 0x6F) of the CiA 402 states (C-018).
pub mod sw {
    /// Switch on disabled.
    pub const SOD: u16 = 0x0040;
    /// Ready to switch on.
    pub const RTSO: u16 = 0x0021;
    /// Switched on.
    pub const SO: u16 = 0x0023;
    /// Operation enabled.
    pub const OE: u16 = 0x0027;
    /// Quick stop active.
    pub const QSA: u16 = 0x0007;
    /// Fault reaction active.
    pub const FRA: u16 = 0x000F;
    /// Fault.
    pub const FAULT: u16 = 0x0008;
}

/// A master running the standard process data of one drive in Op: each
/// [`cycle`](Self::cycle) writes the outputs, lets the simulated line run one
/// master cycle (1 ms: the drive's control cycle and polls), then exchanges
/// the process data (one LRW) and decodes the drive's TxPDO.
pub struct Cyclic<'a> {
    /// The drive, its group and master.
    pub link: Link<'a>,
    /// The RxPDO image sent every cycle.
    pub out: [u8; RXPDO_LEN],
    /// The last TxPDO received.
    pub tx: TxPdo,
    /// Master cycles run so far.
    pub cycles: u64,
}

/// Drive `slave` of `group` (in Op) on the simulated line `sim` with the
/// master `md`: what [`Cyclic`] and [`RawCyclic`] exchange process data
/// with.
#[derive(Clone, Copy)]
pub struct Link<'a> {
    /// The master.
    pub md: &'a MainDevice<'a>,
    /// The group in Op.
    pub group: &'a OpGroup,
    /// The simulated line.
    pub sim: &'a RefCell<Simulation>,
    /// Position of the drive in the group.
    pub slave: usize,
}

impl Link<'_> {
    /// The lengths of the drive's outputs and inputs as ethercrab configured
    /// them.
    fn lengths(&self) -> (usize, usize) {
        let sd = self.group.subdevice(self.md, self.slave).expect("subdevice");
        let io = sd.io_raw();
        (io.outputs().len(), io.inputs().len())
    }

    /// One master cycle of the drive: `out` written to its outputs, the
    /// simulated time one master cycle on, the frame exchanged (both its
    /// outputs written and inputs read, WKC 3); `read` of its inputs.
    async fn exchange<R>(&self, out: &[u8], read: impl FnOnce(&[u8]) -> R) -> R {
        let sd = self.group.subdevice(self.md, self.slave).expect("subdevice");
        sd.outputs_raw_mut().copy_from_slice(out);
        {
            let mut sim = self.sim.borrow_mut();
            let t = sim.now() + MASTER_CYCLE;
            sim.advance_to(t);
        }
        let r = self.group.tx_rx(self.md).await.expect("process data cycle");
        assert_eq!(r.working_counter, 3, "outputs written and inputs read");
        let io = sd.io_raw();
        read(io.inputs())
    }
}

impl<'a> Cyclic<'a> {
    /// A master on drive `slave` of `group`; the outputs start all zero
    /// (controlword 0, mode 0).
    pub fn new(
        md: &'a MainDevice<'a>,
        group: &'a OpGroup,
        sim: &'a RefCell<Simulation>,
        slave: usize,
    ) -> Self {
        let link = Link {
            md,
            group,
            sim,
            slave,
        };
        let (o, i) = link.lengths();
        assert_eq!(o, RXPDO_LEN, "standard RxPDO length");
        assert_eq!(i, TXPDO_LEN, "standard TxPDO length");
        Self {
            link,
            out: [0; RXPDO_LEN],
            tx: TxPdo::default(),
            cycles: 0,
        }
    }

    fn put(&mut self, offset: usize, bytes: &[u8]) {
        self.out[offset..offset + bytes.len()].copy_from_slice(bytes);
    }

    /// 6040h controlword @0.
    pub fn set_controlword(&mut self, cw: u16) {
        self.put(0, &cw.to_le_bytes());
    }

    /// The controlword being sent.
    pub fn controlword(&self) -> u16 {
        u16::from_le_bytes([self.out[0], self.out[1]])
    }

    /// 6060h modes of operation @2.
    pub fn set_mode(&mut self, mode: i8) {
        self.out[2] = mode as u8;
    }

    /// 607Ah target position @3, inc.
    pub fn set_target_position(&mut self, p: i32) {
        self.put(3, &p.to_le_bytes());
    }

    /// 60FFh target velocity @7, inc/s.
    pub fn set_target_velocity(&mut self, v: i32) {
        self.put(7, &v.to_le_bytes());
    }

    /// 60B1h velocity offset @11, inc/s.
    pub fn set_velocity_offset(&mut self, v: i32) {
        self.put(11, &v.to_le_bytes());
    }

    /// 60B2h torque offset @15, 0.1 %.
    pub fn set_torque_offset(&mut self, t: i16) {
        self.put(15, &t.to_le_bytes());
    }

    /// 6071h target torque @17, 0.1 %.
    pub fn set_target_torque(&mut self, t: i16) {
        self.put(17, &t.to_le_bytes());
    }

    /// One master cycle; returns the TxPDO received.
    pub async fn cycle(&mut self) -> TxPdo {
        self.tx = self.link.exchange(&self.out, TxPdo::decode).await;
        self.cycles += 1;
        self.tx
    }

    /// `n` master cycles; returns the last TxPDO.
    pub async fn run(&mut self, n: usize) -> TxPdo {
        for _ in 0..n {
            self.cycle().await;
        }
        self.tx
    }

    /// Runs up to `max` cycles until `pred` holds for the TxPDO; returns the
    /// number of cycles it took, `None` if it never held.
    pub async fn run_until(&mut self, max: usize, mut pred: impl FnMut(&TxPdo) -> bool) -> Option<usize> {
        for k in 1..=max {
            let tx = self.cycle().await;
            if pred(&tx) {
                return Some(k);
            }
        }
        None
    }

    /// Sends `cw` until the statusword state (& 0x6F) is `state`, at most
    /// `max` cycles; panics otherwise.
    pub async fn command(&mut self, cw: u16, state: u16, max: usize) -> TxPdo {
        self.set_controlword(cw);
        let ok = self.run_until(max, |t| t.state() == state).await;
        assert!(
            ok.is_some(),
            "controlword {cw:#06x}: statusword {:#06x}, expected state {state:#06x}",
            self.tx.statusword
        );
        self.tx
    }

    /// Shutdown (6), switch on (7), enable operation (15), each until its
    /// state shows in the TxPDO.
    pub async fn enable(&mut self) -> TxPdo {
        self.command(0x0006, sw::RTSO, 20).await;
        self.command(0x0007, sw::SO, 20).await;
        self.command(0x000F, sw::OE, 20).await
    }

    /// Controlword 0 for two cycles, the fault reset (bit 7) until Switch on
    /// disabled ([`Self::command`], 20 cycles at most), 0 for two cycles,
    /// then [`Self::enable`].
    pub async fn reset_and_enable(&mut self) -> TxPdo {
        self.set_controlword(0);
        self.run(2).await;
        self.command(axis::CW_FAULT_RESET, sw::SOD, 20).await;
        self.set_controlword(0);
        self.run(2).await;
        self.enable().await
    }

    /// Enabled in csv ([`Self::enable_in`] 9), then `n` cycles at the target
    /// velocity `v` (inc/s).
    pub async fn csv_at(&mut self, v: i32, n: usize) -> TxPdo {
        self.enable_in(9).await;
        self.set_target_velocity(v);
        self.run(n).await
    }

    /// Enabled in csv ([`Self::enable_in`] 9) at the target velocity `v`
    /// (inc/s) until the axis runs within 1/20 rev/s of it (500 cycles at
    /// most; panics otherwise), then 20 cycles more.
    pub async fn csv_reach(&mut self, v: i32) -> TxPdo {
        self.enable_in(9).await;
        self.set_target_velocity(v);
        self.run_until(500, |t| (t.velocity - v).abs() < REV / 20)
            .await
            .unwrap_or_else(|| panic!("running at {v} inc/s"));
        self.run(20).await
    }

    /// Mode `mode` (6060h) for three cycles, then [`Self::enable`].
    pub async fn enable_in(&mut self, mode: i8) -> TxPdo {
        self.set_mode(mode);
        self.run(3).await;
        self.enable().await
    }

    /// Simulated time.
    pub fn now(&self) -> Nanos {
        self.link.sim.borrow().now()
    }
}

// ---------------------------------------------------------------------------
// Cyclic process data with a remapped layout (tests/tests/motion_more.rs)
// ---------------------------------------------------------------------------

/// Writes the mode map `layout` of axis A into 1600h/1A00h by SDO (Pre-Op),
/// the CiA 301 sequence a master's start-up list uses.
pub async fn map_layout<S>(sd: &SubDeviceRef<'_, S>, layout: drive_ecat::PdoLayout)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let (rx, tx) = layout.entries();
    for (pdo, entries) in [(0x1600u16, rx), (0x1A00, tx)] {
        let entries: Vec<u32> = entries.iter().map(|e| e.mapping_value()).collect();
        map_pdo(sd, pdo, &entries).await;
    }
}

/// Writes the mapping `entries` (index << 16 | sub << 8 | bits) into `pdo`
/// by SDO (Pre-Op) as a master's start-up list does: sub 0 = 0, the
/// entries from sub 1, sub 0 = their number.
pub async fn map_pdo<S>(sd: &SubDeviceRef<'_, S>, pdo: u16, entries: &[u32])
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    sd.sdo_write(pdo, 0, 0u8).await.expect("sub 0 = 0");
    for (sub, &e) in (1u8..).zip(entries) {
        sd.sdo_write(pdo, sub, e).await.expect("entry");
    }
    sd.sdo_write(pdo, 0, entries.len() as u8)
        .await
        .expect("sub 0 = n");
}

/// A master running any process image of one drive in Op as raw bytes (the
/// ip and vl maps): like [`Cyclic`], without the standard layout. The
/// controlword sits at byte 0 and 6060h at byte 2 of the RxPDO, the
/// statusword at byte 0 of the TxPDO in every map.
pub struct RawCyclic<'a> {
    /// The drive, its group and master.
    pub link: Link<'a>,
    /// The RxPDO image sent every cycle.
    pub out: Vec<u8>,
    /// The last TxPDO received.
    pub inputs: Vec<u8>,
    /// Master cycles run so far.
    pub cycles: u64,
}

impl<'a> RawCyclic<'a> {
    /// A master on the drive of `link` with the lengths ethercrab
    /// configured; the outputs start all zero.
    pub fn new(link: Link<'a>) -> Self {
        let (o, i) = link.lengths();
        Self {
            link,
            out: vec![0; o],
            inputs: vec![0; i],
            cycles: 0,
        }
    }

    /// Writes `bytes` into the RxPDO at `offset`.
    pub fn put(&mut self, offset: usize, bytes: &[u8]) {
        self.out[offset..offset + bytes.len()].copy_from_slice(bytes);
    }

    /// 6040h controlword @0.
    pub fn set_controlword(&mut self, cw: u16) {
        self.put(0, &cw.to_le_bytes());
    }

    /// 6060h modes of operation @2.
    pub fn set_mode(&mut self, mode: i8) {
        self.out[2] = mode as u8;
    }

    /// TxPDO u16 at `o`.
    pub fn u16_at(&self, o: usize) -> u16 {
        u16::from_le_bytes([self.inputs[o], self.inputs[o + 1]])
    }

    /// TxPDO i16 at `o`.
    pub fn i16_at(&self, o: usize) -> i16 {
        self.u16_at(o) as i16
    }

    /// TxPDO i32 at `o`.
    pub fn i32_at(&self, o: usize) -> i32 {
        i32::from_le_bytes(self.inputs[o..o + 4].try_into().expect("4 bytes"))
    }

    /// 6041h statusword @0.
    pub fn statusword(&self) -> u16 {
        self.u16_at(0)
    }

    /// Statusword & 0x6F.
    pub fn state(&self) -> u16 {
        self.statusword() & 0x6F
    }

    /// Statusword bit `n`.
    pub fn bit(&self, n: u8) -> bool {
        self.statusword() & (1 << n) != 0
    }

    /// 6061h @2.
    pub fn mode_display(&self) -> i8 {
        self.inputs[2] as i8
    }

    /// One master cycle (see [`Cyclic::cycle`]).
    pub async fn cycle(&mut self) {
        let inputs = &mut self.inputs;
        self.link.exchange(&self.out, |i| inputs.copy_from_slice(i)).await;
        self.cycles += 1;
    }

    /// `n` master cycles.
    pub async fn run(&mut self, n: usize) {
        for _ in 0..n {
            self.cycle().await;
        }
    }

    /// Runs up to `max` cycles until `pred` holds; returns the cycles it took.
    pub async fn run_until(&mut self, max: usize, mut pred: impl FnMut(&Self) -> bool) -> Option<usize> {
        for k in 1..=max {
            self.cycle().await;
            if pred(self) {
                return Some(k);
            }
        }
        None
    }

    /// Shutdown, switch on, enable operation (the bits in `extra` added to
    /// enable operation), each until its state shows.
    pub async fn enable(&mut self, extra: u16) {
        for (cw, state) in [(0x0006, sw::RTSO), (0x0007, sw::SO), (0x000F | extra, sw::OE)] {
            self.set_controlword(cw);
            let ok = self.run_until(20, |c| c.state() == state).await;
            assert!(
                ok.is_some(),
                "controlword {cw:#06x}: statusword {:#06x}",
                self.statusword()
            );
        }
    }
}
