//! Which [`ScheduleMode`] the devices can run, and why.

use super::{ScheduleMode, SchedulerOptions};
use crate::context::GpuContext;
use crate::error::{Error, Result};

pub(super) fn unavailable(mode: ScheduleMode, reason: &str) -> Error {
    Error::ModeUnavailable { mode: mode.name(), reason: reason.to_owned() }
}

/// The mode for `options` on `render`, and why.
pub(super) fn choose_mode(render: &GpuContext, options: &SchedulerOptions) -> Result<(ScheduleMode, String)> {
    let device = &render.device;
    let second_queue = match device.compute {
        Some(q) if q.family != device.graphics.family => Some(format!("compute queue family {}", q.family)),
        Some(_) => Some(format!("a second queue of graphics family {}", device.graphics.family)),
        None => None,
    };
    let no_queue = format!("{} offers no second queue (one queue family with one queue)", device.info.name);
    match options.mode {
        Some(ScheduleMode::SingleQueue) => Ok((ScheduleMode::SingleQueue, "forced by the host".into())),
        Some(ScheduleMode::AsyncCompute) => match (second_queue, options.async_on_graphics_queue) {
            (Some(q), _) => Ok((ScheduleMode::AsyncCompute, format!("forced by the host, on {q}"))),
            (None, true) => {
                Ok((ScheduleMode::AsyncCompute, format!("forced by the host on the graphics queue: {no_queue}")))
            }
            (None, false) => Err(unavailable(ScheduleMode::AsyncCompute, &no_queue)),
        },
        Some(ScheduleMode::SecondDevice) => match &options.sim_device {
            Some(_) => Ok((ScheduleMode::SecondDevice, "forced by the host".into())),
            None => Err(unavailable(ScheduleMode::SecondDevice, "no sim_device given")),
        },
        None => Ok(match (&options.sim_device, second_queue) {
            (Some(s), _) => (ScheduleMode::SecondDevice, format!("the host gave simulation device {}", s.info().name)),
            (None, Some(q)) => (ScheduleMode::AsyncCompute, format!("the device has {q}")),
            (None, None) => (ScheduleMode::SingleQueue, no_queue),
        }),
    }
}
