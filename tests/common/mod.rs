//! Shared by the integration tests: a validated headless context.

use vkhair::groom::grow::{grow, GrowParams};
use vkhair::groom::scenes;
use vkhair::{ContextOptions, GpuContext, Groom, ValidationLog};

/// Key hairs grown on the `thesis` scalp: `strands` × `points`, 0.35 m long with
/// segments 1.5× longer toward the tip, from `seed`.
#[allow(dead_code, reason = "not every test file grows its own groom")]
pub fn grown_groom(strands: usize, points: usize, seed: u64) -> Groom {
    let p = GrowParams {
        strands,
        points_per_strand: points,
        length: 0.35,
        segment_growth: 1.5,
        seed,
        ..GrowParams::default()
    };
    grow(&scenes::thesis_scalp(), &p).expect("groom")
}

/// A headless context with validation and synchronization validation; dropping it
/// fails the test on any validation message (objects leaked at teardown included).
#[allow(dead_code, reason = "test files with their own contexts use only the helpers")]
pub struct Gpu {
    ctx: Option<GpuContext>,
    log: ValidationLog,
}

#[allow(dead_code, reason = "as above")]
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
