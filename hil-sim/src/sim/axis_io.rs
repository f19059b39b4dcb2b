//! What a simulated drive's axes read from their motors and conditions
//! ([`AxisIo`]) each control cycle.

use super::AxisConditions;
use crate::motor::{Input, Motor, MotorOutputs};
use drive_ecat::axis::{AxisIo, IndexLatch, ProbeEdge, SwitchEdge, SwitchId};

/// What the axis runtime reads from the motor's last step.
pub(crate) fn axis_io(out: Option<&MotorOutputs>, motor: &Motor, c: AxisConditions) -> AxisIo {
    let mut io = AxisIo::ready(0);
    io.additional_enable = c.additional_enable;
    io.supply_ok = c.supply_ok;
    io.sto_active = c.sto_active;
    io.encoder_ok = c.encoder_ok;
    let Some(out) = out else {
        io.position_inc = motor.position_inc_i64() as i32;
        return io;
    };
    io.position_inc = out.position_inc;
    let sw = motor.switches();
    // electrical level -> "switch actuated" (normally closed contacts read low when hit)
    let hit = |which: Input| out.inputs.get(which) != sw.get(which).is_active_low();
    io.limit_positive = hit(Input::PositiveLimit);
    io.limit_negative = hit(Input::NegativeLimit);
    io.reference = hit(Input::Reference);
    io.index = out.index.map(|i| IndexLatch {
        position_inc: i.position_inc,
        time_ns: out.step_start + i.time_offset,
    });
    let probes = out.edges.iter().filter_map(|e| {
        let input = match e.input {
            Input::Probe1 => 1,
            Input::Probe2 => 2,
            _ => return None,
        };
        Some(ProbeEdge {
            input,
            rising: e.rising,
            time_ns: out.step_start + e.time_offset,
            position_inc: Some(e.position_inc),
        })
    });
    for (slot, edge) in io.probe_edges.iter_mut().zip(probes) {
        *slot = Some(edge);
    }
    // limit and reference switch changes, latched where the motor crossed them
    let switches = out.edges.iter().filter_map(|e| {
        let switch = match e.input {
            Input::PositiveLimit => SwitchId::PositiveLimit,
            Input::NegativeLimit => SwitchId::NegativeLimit,
            Input::Reference => SwitchId::Reference,
            _ => return None,
        };
        Some(SwitchEdge {
            switch,
            position_inc: e.position_inc,
        })
    });
    for (slot, edge) in io.switch_edges.iter_mut().zip(switches) {
        *slot = Some(edge);
    }
    io
}
