//! Segmented SDO upload throughput for a 4 KiB object, through the whole
//! chain: ethercrab (in-process) -> simulated ESC -> slave stack (CoE server).
//!
//! `cargo bench -p drive-tests --bench sdo [-- --reads N]`
//!
//! The drive's dictionary has no object of 4 KiB, so the benchmark slave
//! serves the drive's objects plus one 4 KiB OCTET_STRING at 5FFFh. The
//! upload is driven with raw mailbox frames ([`drive_tests::CoeClient`]):
//! ethercrab 0.7.1's `sdo_read` cannot decode an upload-segment response
//! (its `CoeCommand` has no value for scs = 0).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use drive_ecat::DriveObjects;
use drive_tests::CoeClient;
use hil_sim::esc::{Esc, EscConfig};
use hil_sim::sim::{Node, Simulation};
use od::{Access, CommState, DataType, Dictionary, EntryInfo, ObjectCode, ObjectInfo, SdoAbort};
use std::cell::RefCell;
use std::time::Instant;

const BIG: u16 = 0x5FFF;
const BIG_LEN: usize = 4096;
static BIG_ENTRIES: [EntryInfo; 1] = [EntryInfo::new(
    0,
    "Benchmark block",
    DataType::OctetString(BIG_LEN as u16),
    Access::RO,
)];
static BIG_OBJECT: ObjectInfo = ObjectInfo {
    index: BIG,
    name: "Benchmark block",
    code: ObjectCode::Var,
    entries: od::Entries::slice(&BIG_ENTRIES),
};

/// The drive's dictionary plus the 4 KiB block.
struct BenchDict(DriveObjects);

/// A 1 ms cycle, no RxPDO monitoring (the defaults).
impl ecat::Application for BenchDict {}

impl Dictionary for BenchDict {
    fn object(&self, index: u16) -> Option<&'static ObjectInfo> {
        if index == BIG {
            Some(&BIG_OBJECT)
        } else {
            self.0.object(index)
        }
    }
    fn next_object(&self, after: Option<u16>) -> Option<&'static ObjectInfo> {
        self.0.next_object(after)
    }
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], state: CommState) -> Result<usize, SdoAbort> {
        if index != BIG {
            return self.0.read(index, sub, buf, state);
        }
        let dst = buf.get_mut(..BIG_LEN).ok_or(SdoAbort::OUT_OF_MEMORY)?;
        for (i, b) in dst.iter_mut().enumerate() {
            *b = i as u8;
        }
        Ok(BIG_LEN)
    }
    fn write(&mut self, index: u16, sub: u8, data: &[u8], state: CommState) -> Result<(), SdoAbort> {
        self.0.write(index, sub, data, state)
    }
    fn process_data_bytes(&self) -> Option<(usize, usize)> {
        self.0.process_data_bytes()
    }
}

struct BenchNode {
    esc: Esc,
    slave: ecat::Slave,
    dict: BenchDict,
}

impl Node for BenchNode {
    fn esc_mut(&mut self) -> &mut Esc {
        &mut self.esc
    }
    fn poll(&mut self, now: nanos::Nanos) {
        self.esc.tick(now);
        let _ = self.slave.poll(&mut self.esc.pdi(), &mut self.dict, now);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let reads: usize = args
        .iter()
        .position(|a| a == "--reads")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    let mut sii = [0u8; ecat::sii::EEPROM_BYTES];
    let n = ecat::build_sii(&drive_ecat::DEVICE, &mut sii).expect("SII");
    let node = BenchNode {
        esc: Esc::new(EscConfig::default(), &sii[..n]),
        slave: ecat::Slave::new(&drive_ecat::DEVICE),
        dict: BenchDict(DriveObjects::new()),
    };
    let sim = RefCell::new(Simulation::with_nodes(vec![node]));
    let (wall, sim_ns, frames) = hil_sim::master::with_first_subdevice(&sim, async |sd, _clock| {
        let mut coe = CoeClient::new();
        let first = coe.upload(&sd, BIG, 0).await.expect("4 KiB upload");
        assert!(first.iter().enumerate().all(|(i, &b)| b == i as u8), "content");
        let (t0, f0) = {
            let s = sim.borrow();
            (s.now().as_ns(), s.frames())
        };
        let start = Instant::now();
        for _ in 0..reads {
            assert_eq!(
                coe.upload(&sd, BIG, 0).await.expect("4 KiB upload").len(),
                BIG_LEN
            );
        }
        let wall = start.elapsed();
        let s = sim.borrow();
        (wall, s.now().as_ns() - t0, s.frames() - f0)
    })
    .expect("the line's first SubDevice");
    let bytes = (reads * BIG_LEN) as f64;
    println!("segmented SDO upload of a {BIG_LEN}-byte object, {reads} uploads, mailbox 256 bytes");
    println!("{:<34} {:>14}", "frames per upload", frames as f64 / reads as f64);
    println!(
        "{:<34} {:>14.0}",
        "bytes per second of simulated time",
        bytes / (sim_ns as f64 / 1e9)
    );
    println!(
        "{:<34} {:>14.0}",
        "bytes per wall-clock second",
        bytes / wall.as_secs_f64()
    );
    println!(
        "{:<34} {:>14.3}",
        "simulated ms per upload",
        sim_ns as f64 / 1e6 / reads as f64
    );
}
