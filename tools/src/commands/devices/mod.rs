//! `vkhair devices`: the Vulkan devices, what vkhair can use of each, and the
//! one it would choose.

use vkhair::ash::vk;
use vkhair::{list_devices, ContextOptions};

use crate::output::CliResult;
use crate::say;

pub fn devices() -> CliResult {
    let options = ContextOptions::default();
    let reports = list_devices(&options)?;
    if reports.is_empty() {
        say!("no Vulkan devices (install mesa-vulkan-drivers for lavapipe)");
    }
    for r in &reports {
        let i = &r.info;
        let kind = match i.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
            vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
            vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
            vk::PhysicalDeviceType::CPU => "CPU",
            _ => "other",
        };
        say!(
            "{} {} ({kind}, Vulkan {}.{}.{}, {})",
            if r.chosen { "*" } else { " " },
            i.name,
            vk::api_version_major(i.api_version),
            vk::api_version_minor(i.api_version),
            vk::api_version_patch(i.api_version),
            i.driver
        );
        match &r.usable {
            Ok(()) => say!("    usable: yes"),
            Err(why) => say!("    usable: no — {why}"),
        }
        say!(
            "    timestamps: {} valid bits, {} ns/tick; shared memory {} KiB; workgroup ≤ {}; tessellation ≤ {}",
            i.timestamp_valid_bits,
            i.timestamp_period,
            i.max_compute_shared_memory / 1024,
            i.max_compute_invocations,
            i.max_tessellation_level
        );
        say!("    async compute queue: {}", if r.async_compute { "yes" } else { "no (single queue path)" });
        say!(
            "    subgroup arithmetic: {}",
            if i.subgroup_reductions { "yes" } else { "no (reductions through shared memory)" }
        );
        if !r.optional_extensions.is_empty() {
            say!("    optional extensions: {}", r.optional_extensions.join(", "));
        }
    }
    say!("(* = chosen; force a device with {}=<name substring>)", vkhair::DEVICE_ENV);
    match &options.device_name {
        Some(name) if !reports.iter().any(|r| r.chosen) => Err(format!(
            "{}={name:?} matches no usable device above: vkhair would choose none (unset it to choose the best)",
            vkhair::DEVICE_ENV
        )
        .into()),
        _ => Ok(()),
    }
}
