//! The PROFINET images' log of device events.

use profinet::cm::CmEvent;
use profinet::device::{DeviceEvent, RtEvent};

/// One line per device event the operator cares about.
pub fn log_event(e: &DeviceEvent) {
    match e {
        DeviceEvent::Dcp(_) => defmt::info!("pn: DCP set/signal/reset"),
        DeviceEvent::Cm(CmEvent::Connected(_)) => defmt::info!("pn: AR connected"),
        DeviceEvent::Cm(CmEvent::Ready(_)) => defmt::info!("pn: AR ready"),
        DeviceEvent::Cm(CmEvent::Released(_)) => defmt::info!("pn: AR released"),
        DeviceEvent::Cm(CmEvent::Aborted(..)) => defmt::warn!("pn: AR aborted"),
        DeviceEvent::Rt(RtEvent::Exchanging(_)) => defmt::info!("pn: cyclic data exchanged"),
        DeviceEvent::Rt(RtEvent::ArLost(_)) => defmt::warn!("pn: AR lost"),
        _ => {}
    }
}
