//! Shared by the integration tests: a validated headless context.

use vkhair::{ContextOptions, GpuContext, ValidationLog};

/// A headless context with validation and synchronization validation; dropping it
/// fails the test on any validation message (objects leaked at teardown included).
pub struct Gpu {
    ctx: Option<GpuContext>,
    log: ValidationLog,
}

impl Gpu {
    pub fn new() -> Gpu {
        let log = ValidationLog::new();
        let ctx = GpuContext::headless(&ContextOptions::validated(&log)).expect("headless context with validation");
        Gpu { ctx: Some(ctx), log }
    }

    pub fn ctx(&self) -> &GpuContext {
        self.ctx.as_ref().expect("alive")
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        drop(self.ctx.take());
        if !std::thread::panicking() {
            self.log.assert_clean();
        }
    }
}
