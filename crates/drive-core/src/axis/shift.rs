//! The drive-generated position set-points one control cycle behind their
//! acceleration feedforward, with identified mechanics (issue 35, B44).
//!
//! The profile generators (pp, the PROFINET positioning records, homing,
//! jog, the stop ramps) give in cycle k the set-point for now, its speed and
//! the acceleration that led to it over the cycle before. The torque the
//! cascade computes now acts over the coming cycle: J·a of the set-point's
//! past cycle comes one cycle late, and every step of the profile's
//! acceleration leaves a speed deficit of a·Δt that the position loop makes
//! up over 1/Kv (about 800 inc at 167 rev/s² on the simulated servo). With
//! identified mechanics (B45 ≠ 0: the feedforward is worth aligning) the
//! cascade and the following-error monitor therefore get the last cycle's
//! set-point and speed with this cycle's acceleration (the change of the
//! generator's speed over it; with it the cascade also compensates the
//! speed measurement's lag, `compensate_velocity_lag`), as drives that
//! "symmetrise" the feedforward do: the axis follows the profile one
//! control cycle later, and 60F4h is measured against that. csp/ip are not
//! shifted (their acceleration is derived from the master's set-points,
//! already a cycle behind).

use super::*;

impl Axis {
    /// With identified mechanics the demand the cascade gets instead of
    /// `demand` ([`shifted`](Self::shifted)); else `None`, the demand as
    /// it is (one compare on the cycle's path).
    #[inline(always)]
    pub(super) fn shift(&mut self, demand: Option<Demand>, dt_ns: u32) -> Option<Demand> {
        let identified = self
            .cascade
            .as_ref()
            .is_some_and(|c| c.config().compensate_velocity_lag);
        if identified {
            Some(self.shifted(demand, dt_ns))
        } else {
            self.last_setpoint = None;
            None
        }
    }

    /// The demand the cascade gets for `demand` with identified mechanics
    /// (the caller checks): shifted as above when a drive-generated
    /// position demand follows another; else `demand` itself.
    fn shifted(&mut self, demand: Option<Demand>, dt_ns: u32) -> Demand {
        let d = demand.unwrap_or(Demand::hold(self.sp_pos));
        let generated = demand.is_some()
            && d.entry == ControlEntry::Position
            && !matches!(self.running, Running::CyclicPosition { .. });
        let last = if generated {
            self.last_setpoint.replace((d.position, d.velocity))
        } else {
            self.last_setpoint.take()
        };
        match last {
            Some((position, velocity)) if dt_ns > 0 => Demand {
                position,
                velocity,
                // the set-point's change of speed over this cycle: what the
                // shifted set-point does over the coming one
                acceleration: (d.velocity - velocity) / (dt_ns as f32 * 1e-9),
                ..d
            },
            _ => d,
        }
    }
}
