//! The record positioning state ([`RecordTasks`]) as bytes in the RAM
//! image (J411's element "Task state", [`TASK_STATE_BYTES`]), so that it
//! takes no room in [`Axis`] or beside the image (see [`RecordTasks`]). All
//! zero bytes are [`RecordTasks::IDLE`] (a restore of J411's defaults drops
//! every task). Little endian; no field is read past the slice.

use super::records::{RecordJog, RecordTasks, Task};
use super::running::VelocityCommand;
use super::{RecordCommand, RecordStatus, StartRefusal};
use crate::objects::records::TASK_STATE_BYTES;
use motion::ProfileLimits;

/// Writes values one after the other into a byte slice (bytes past its
/// end are dropped).
struct Writer<'a> {
    out: &'a mut [u8],
    at: usize,
}

impl Writer<'_> {
    fn bytes(&mut self, b: &[u8]) {
        for v in b {
            if let Some(d) = self.out.get_mut(self.at) {
                *d = *v;
            }
            self.at += 1;
        }
    }
    fn u8(&mut self, v: u8) {
        self.bytes(&[v]);
    }
    fn u16(&mut self, v: u16) {
        self.bytes(&v.to_le_bytes());
    }
    fn i32(&mut self, v: i32) {
        self.bytes(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
}

/// Reads them back (0 past the end).
struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn u8(&mut self) -> u8 {
        let v = self.data.get(self.at).copied().unwrap_or(0);
        self.at += 1;
        v
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }
    fn i32(&mut self) -> i32 {
        i32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }
    fn f32(&mut self) -> f32 {
        f32::from_bits(u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()]))
    }
}

/// The command's eight inputs as bits 0…7.
pub(super) fn command_bits(c: &RecordCommand) -> u8 {
    [
        c.enable,
        c.proceed,
        c.start,
        c.relative,
        c.immediate,
        c.jog_positive,
        c.jog_negative,
        c.setup_mode,
    ]
    .iter()
    .enumerate()
    .fold(0, |b, (k, on)| b | (u8::from(*on) << k))
}

/// The command of [`command_bits`].
pub(super) fn command_of(b: u8) -> RecordCommand {
    let bit = |k: u8| b & (1 << k) != 0;
    RecordCommand {
        enable: bit(0),
        proceed: bit(1),
        start: bit(2),
        relative: bit(3),
        immediate: bit(4),
        jog_positive: bit(5),
        jog_negative: bit(6),
        setup_mode: bit(7),
    }
}

fn refusal_code(r: Option<StartRefusal>) -> u8 {
    match r {
        None => 0,
        Some(StartRefusal::SoftwareLimit) => 1,
        Some(StartRefusal::NotReferenced) => 2,
        Some(StartRefusal::Direction) => 3,
        Some(StartRefusal::InvalidRecord) => 4,
        Some(StartRefusal::Busy) => 5,
    }
}

fn refusal_of(b: u8) -> Option<StartRefusal> {
    Some(match b {
        1 => StartRefusal::SoftwareLimit,
        2 => StartRefusal::NotReferenced,
        3 => StartRefusal::Direction,
        4 => StartRefusal::InvalidRecord,
        5 => StartRefusal::Busy,
        _ => return None,
    })
}

/// A status packed into a word (kept in the axis for
/// [`super::Axis::record_status`]): bits 0…5 flags, 8…10 refusal, 16…31
/// record.
pub(super) fn status_bits(s: &RecordStatus) -> u32 {
    u32::from(status_flags(s))
        | (u32::from(refusal_code(s.refused)) << 8)
        | (u32::from(s.record.unwrap_or(0)) << 16)
}

/// A status' six flags as bits 0…5 (acknowledge, target reached, stopped,
/// waiting, jogging, a record selected): the packed word's and the saved
/// state's.
fn status_flags(s: &RecordStatus) -> u8 {
    flags(&[
        s.acknowledge,
        s.target_reached,
        s.stopped,
        s.waiting,
        s.jogging,
        s.record.is_some(),
    ])
}

/// The status of [`status_bits`].
pub(super) fn status_of(b: u32) -> RecordStatus {
    let f = |k: u32| b & (1 << k) != 0;
    RecordStatus {
        acknowledge: f(0),
        target_reached: f(1),
        stopped: f(2),
        waiting: f(3),
        jogging: f(4),
        record: f(5).then_some((b >> 16) as u16),
        refused: refusal_of((b >> 8) as u8 & 7),
    }
}

fn flags(bits: &[bool]) -> u8 {
    bits.iter()
        .enumerate()
        .fold(0, |b, (k, on)| b | (u8::from(*on) << k))
}

fn write_task(w: &mut Writer<'_>, t: &Option<Task>) {
    match t {
        None => w.bytes(&[0; 23]),
        Some(t) => {
            w.u8(1);
            w.u16(t.record);
            w.i32(t.target);
            w.f32(t.limits.velocity);
            w.f32(t.limits.acceleration);
            w.f32(t.limits.deceleration);
            w.f32(t.end_velocity);
        }
    }
}

fn read_task(r: &mut Reader<'_>) -> Option<Task> {
    let present = r.u8() != 0;
    let t = Task {
        record: r.u16(),
        target: r.i32(),
        limits: ProfileLimits {
            velocity: r.f32(),
            acceleration: r.f32(),
            deceleration: r.f32(),
            // record tasks have no jerk limit (P-147)
            jerk: f32::INFINITY,
        },
        end_velocity: r.f32(),
    };
    present.then_some(t)
}

impl RecordTasks {
    /// The state as bytes ([`TASK_STATE_BYTES`]).
    pub(crate) fn to_bytes(self) -> [u8; TASK_STATE_BYTES] {
        let mut out = [0u8; TASK_STATE_BYTES];
        let mut w = Writer { out: &mut out, at: 0 };
        match self.command {
            Some(c) => {
                w.u8(1);
                w.u8(command_bits(&c));
            }
            None => w.bytes(&[0, 0]),
        }
        w.u8(command_bits(&self.prev));
        write_task(&mut w, &self.current);
        write_task(&mut w, &self.next);
        match self.jog {
            None => w.bytes(&[0; 12]),
            Some(j) => {
                w.u8(1);
                w.u16(j.record);
                w.f32(j.dir);
                w.u8(flags(&[j.command.commanded.is_some(), j.command.halting]));
                w.f32(j.command.commanded.unwrap_or(0.0));
            }
        }
        w.u8(flags(&[
            self.halted,
            self.planned_setup,
            self.ack,
            self.finished,
            self.braking,
        ]));
        w.u16(self.planned_override);
        w.u8(refusal_code(self.refused));
        let s = &self.status;
        w.u8(status_flags(s));
        w.u16(s.record.unwrap_or(0));
        w.u8(refusal_code(s.refused));
        out
    }

    /// The state of `data` (zeros: [`RecordTasks::IDLE`]).
    pub(crate) fn from_bytes(data: &[u8]) -> RecordTasks {
        let mut r = Reader { data, at: 0 };
        let present = r.u8() != 0;
        let bits = r.u8();
        let command = present.then(|| command_of(bits));
        let prev = command_of(r.u8());
        let current = read_task(&mut r);
        let next = read_task(&mut r);
        let jog_present = r.u8() != 0;
        let record = r.u16();
        let dir = r.f32();
        let jf = r.u8();
        let commanded = r.f32();
        let jog = jog_present.then_some(RecordJog {
            record,
            dir,
            command: VelocityCommand {
                commanded: (jf & 1 != 0).then_some(commanded),
                halting: jf & 2 != 0,
            },
        });
        let f = r.u8();
        let planned_override = r.u16();
        let refused = refusal_of(r.u8());
        let sf = r.u8();
        let record = r.u16();
        let status_refused = refusal_of(r.u8());
        RecordTasks {
            command,
            prev,
            current,
            next,
            jog,
            halted: f & 1 != 0,
            planned_setup: f & 2 != 0,
            ack: f & 4 != 0,
            finished: f & 8 != 0,
            braking: f & 16 != 0,
            planned_override,
            refused,
            status: RecordStatus {
                acknowledge: sf & 1 != 0,
                target_reached: sf & 2 != 0,
                stopped: sf & 4 != 0,
                waiting: sf & 8 != 0,
                jogging: sf & 16 != 0,
                record: (sf & 32 != 0).then_some(record),
                refused: status_refused,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Zeros are IDLE, and a busy state comes back as it went in.
    #[test]
    fn record_state_round_trip() {
        assert_eq!(RecordTasks::from_bytes(&[0; TASK_STATE_BYTES]), RecordTasks::IDLE);
        assert_eq!(RecordTasks::from_bytes(&[]), RecordTasks::IDLE);
        let task = Task {
            record: 266,
            target: -123_456,
            limits: ProfileLimits {
                velocity: 1.5e6,
                acceleration: 2.5e7,
                deceleration: 3.5e7,
                jerk: f32::INFINITY,
            },
            end_velocity: 4.0e5,
        };
        let busy = RecordTasks {
            command: Some(command_of(0b1010_0111)),
            prev: command_of(0b0101_1000),
            current: Some(task),
            next: Some(Task { record: 7, ..task }),
            jog: Some(RecordJog {
                record: 260,
                dir: -1.0,
                command: VelocityCommand {
                    commanded: Some(-3.0e5),
                    halting: true,
                },
            }),
            halted: true,
            planned_override: 1500,
            planned_setup: true,
            ack: true,
            finished: false,
            braking: true,
            refused: Some(StartRefusal::Busy),
            status: RecordStatus {
                acknowledge: true,
                target_reached: false,
                stopped: true,
                record: Some(266),
                waiting: true,
                jogging: false,
                refused: Some(StartRefusal::SoftwareLimit),
            },
        };
        assert_eq!(RecordTasks::from_bytes(&busy.to_bytes()), busy);
        assert_eq!(status_of(status_bits(&busy.status)), busy.status);
        assert_eq!(status_of(0), RecordStatus::default());
        let c = command_of(0b1100_0011);
        assert_eq!(command_of(command_bits(&c)), c);
    }
}
