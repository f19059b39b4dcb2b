//! The actual values of a cycle back into the dictionary: statusword and
//! the values of the mode (6041h, 6064h, 606Ch, 6077h/6078h from the
//! measured current, …), user units,
//! the causes of Switch on disabled (E47/E49), A67 and 60FDh.

use super::*;
use crate::objects::cycle as f;

impl Axis {
    pub(super) fn write_back(
        &mut self,
        od: &mut DriveObjects,
        out: &Outputs,
        (bits, actual, torque, fe): (u16, i32, f32, i32),
        measured: Option<CurrentActual>,
    ) {
        let mut sw =
            out.statusword & !(SW_TARGET_REACHED | SW_MODE_BIT12 | SW_MODE_BIT13 | SW_INTERNAL_LIMIT);
        let enabled = out.state == State::OperationEnabled;
        if enabled || out.state == State::QuickStopActive {
            sw |= bits & SW_TARGET_REACHED;
        }
        if enabled {
            sw |= bits & (SW_MODE_BIT12 | SW_MODE_BIT13);
        }
        if out.drive_function {
            sw |= bits & SW_INTERNAL_LIMIT;
        }
        od.cycle_write(self.window.axis, f::STATUSWORD, sw);
        let e80 = match self.denial {
            Some(DenialCause::IllegalDirection) => 15,
            Some(
                DenialCause::HardwarePositive
                | DenialCause::HardwareNegative
                | DenialCause::SoftwarePositive
                | DenialCause::SoftwareNegative,
            ) => 20,
            _ => 0u8,
        };
        od.cycle_write(self.window.axis, f::E80_FIELD, e80);
        od.cycle_write(self.window.axis, f::MODE_DISPLAY, out.mode_display);
        let position = self.user_position(actual);
        od.cycle_write(self.window.axis, f::POSITION, sat_i32(position));
        let v = self.scaling.velocity_to_user(self.velocity) * self.velocity_decimals;
        od.cycle_write(self.window.axis, f::VELOCITY, round_i32(v));
        // 6077h in 0.1 % of the rated torque, 6078h in 0.1 % of the rated
        // current (CiA 402: 6076h, 6075h); without a measurement both show the
        // demand (an ideal current loop: the same fraction of either)
        let per_mille = |v: f32, rated: f32| {
            let x = if rated > 0.0 { v / rated * 1000.0 } else { 0.0 };
            round_i32(x).clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16
        };
        let (rated_a, rated_nm) = (self.motor.rated_current_a, self.motor.rated_torque_nm());
        let (t, i) = match measured {
            Some(m) => (per_mille(m.torque_nm, rated_nm), per_mille(m.current_a, rated_a)),
            None => {
                let t = per_mille(torque, rated_nm);
                (t, t)
            }
        };
        od.cycle_write(self.window.axis, f::TORQUE, t);
        od.cycle_write(self.window.axis, f::CURRENT, i);
        od.cycle_write(self.window.axis, f::FOLLOWING_ERROR, sat_i32(self.user(fe)));
        od.cycle_write(self.window.axis, f::PROBE_STATUS, self.probe.status());
        if !self.probe_shown {
            let probe = [
                self.probe.value_60ba(),
                self.probe.value_60bb(),
                self.probe.value_60bc(),
                self.probe.value_60bd(),
            ];
            for (field, value) in f::PROBE_VALUES.into_iter().zip(probe) {
                od.cycle_write(self.window.axis, field, sat_i32(self.user_position(value)));
            }
            self.probe_shown = true;
        }
        od.cycle_write(self.window.axis, f::ADDITIONAL_POSITION, sat_i32(position));
        let rpm = |v: f32| round_i32(v / RPM_TO_INC_PER_S).clamp(-32768, 32767) as i16;
        od.cycle_write(self.window.axis, f::VL_DEMAND, rpm(self.vl_demand));
        od.cycle_write(self.window.axis, f::VL_ACTUAL, rpm(self.velocity));
        od.cycle_write(self.window.axis, f::E48_FIELD, e48(out.state));
    }

    /// A position (or distance) in increments as the objects show it: user
    /// units of 6091h/6092h (C-109), wrapped to 32 bits like the counter.
    pub(super) fn user(&self, increments: i32) -> i64 {
        let u = self
            .scaling
            .to_user(i64::from(increments))
            .unwrap_or(i64::from(increments));
        i64::from(u as i32)
    }

    /// A position in increments as the objects show it: user units,
    /// wrapped into 0 … 607Bh:02 − 1 on an endless axis (C-111).
    #[inline]
    pub(super) fn user_position(&self, increments: i32) -> i64 {
        match self.modulo {
            Some(m) => m.wrap(
                self.scaling
                    .to_user(i64::from(increments))
                    .unwrap_or(i64::from(increments)),
            ),
            None => self.user(increments),
        }
    }

    /// Increments of a distance in user units (saturating).
    pub(super) fn increments(&self, user: i64) -> i32 {
        let v = self.scaling.to_increments(user).unwrap_or(user);
        i32::try_from(v).unwrap_or(if v < 0 { i32::MIN } else { i32::MAX })
    }

    /// E47 (first cause) and E49 (all causes) of Switch on disabled
    /// (C-015): STO, supply, additional enable A60, and the controlword
    /// (no Shutdown command). Both 0 outside Switch on disabled.
    pub(super) fn switch_on_disabled_causes(
        &self,
        od: &mut DriveObjects,
        out: &Outputs,
        io: &AxisIo,
        cw: u16,
    ) {
        let mut causes = 0u8;
        if out.state == State::SwitchOnDisabled {
            // Shutdown = xxxx x110 (bit 7 clear): anything else keeps SOD
            let shutdown = cw & 0x0087 == 0x0006;
            for (bit, present) in [
                (0, io.sto_active),
                (1, !io.supply_ok),
                (2, !io.additional_enable),
                (3, !shutdown),
            ] {
                if present {
                    causes |= 1 << bit;
                }
            }
        }
        let first = if causes == 0 {
            0
        } else {
            causes.trailing_zeros() as u8 + 1
        };
        od.cycle_write(self.window.axis, f::E47_FIELD, first);
        od.cycle_write(self.window.axis, f::E49_FIELD, causes);
    }

    /// A67 from the sources in A66 (C-143): bit k is bit `b` of the entry
    /// `index`:`sub` that element k names (index << 16 | sub << 8 | b;
    /// 0 or an unreadable entry: the bit is 0).
    pub(super) fn user_statusword(&self, od: &mut DriveObjects, o: &Snapshot) {
        let mut a67 = 0u16;
        let sources: &[u32] = if o.a66_used { o.a66.as_slice() } else { &[] };
        for (k, &src) in sources.iter().enumerate() {
            let index = (src >> 16) as u16;
            let sub = (src >> 8) as u8;
            let bit = src & 0xFF;
            if src != 0 && bit < 64 && od.get(index, sub).is_ok_and(|v| (v >> bit) & 1 != 0) {
                a67 |= 1 << k;
            }
        }
        od.cycle_write(self.window.axis, f::A67_FIELD, a67);
    }

    /// The switch levels in 60FDh (bit 0 negative limit, bit 1 positive
    /// limit, bit 2 home switch, CiA 402).
    pub(super) fn digital_inputs(&self, od: &mut DriveObjects, io: &AxisIo) {
        let bits =
            u32::from(io.limit_negative) | u32::from(io.limit_positive) << 1 | u32::from(io.reference) << 2;
        od.cycle_write(self.window.axis, f::DIGITAL_INPUTS, bits);
    }
}
