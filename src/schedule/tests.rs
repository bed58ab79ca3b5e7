//! The scheduler's own tests: dying, lost and stuck simulation sides.

use std::time::Duration;

use super::*;
use crate::headless::Submit;
use crate::vk::tests::TestGpu;

/// A SECOND DEVICE scheduler of eight short strands, rendering on `render`,
/// simulating on `sim`.
fn remote(render: &TestGpu, sim: &TestGpu, pipelining: Pipelining, timeout: Duration) -> FrameScheduler {
    let strands: Vec<Vec<glam::Vec3>> = (0..8)
        .map(|k| (0..4).map(|i| glam::Vec3::new(k as f32 * 0.02, 1.7 - 0.05 * i as f32, 0.0)).collect())
        .collect();
    let groom = Groom::from_strands(&strands).expect("groom");
    let options = SchedulerOptions {
        mode: Some(ScheduleMode::SecondDevice),
        sim_device: Some(sim.ctx().clone()),
        pipelining,
        timeout,
        ..SchedulerOptions::default()
    };
    let head = RigidTransform::default();
    FrameScheduler::new(render.ctx(), &groom, &SimParams::default(), &head, &[], &options).expect("scheduler")
}

/// One frame of `s` on `render` with the head still.
fn frame(render: &TestGpu, s: &mut FrameScheduler) -> Result<()> {
    let head = RigidTransform::default();
    // SAFETY: recording command buffer of the rendering device, waited for.
    render.ctx().run_frame("frame", |cmd| unsafe { s.record_frame(cmd, &[head], None) })
}

/// A worker that dies mid-run (it panics, or its device reports
/// `VK_ERROR_DEVICE_LOST`) turns into typed errors for the host from the next
/// frame calls, in bounded time, for each pipelining choice; dropping the
/// scheduler afterwards joins the dead worker without hanging.
#[test]
fn a_dying_worker_gives_errors_not_hangs() {
    let render = TestGpu::new();
    let sim = TestGpu::new();
    let failures = [Pipelining::Latency, Pipelining::Throughput].into_iter().flat_map(|p| [(p, true), (p, false)]);
    for (pipelining, panic) in failures {
        let mut s = remote(&render, &sim, pipelining, Duration::from_secs(20));
        frame(&render, &mut s).expect("first frame");
        let expected = if panic {
            s.inject_worker_panic().expect("worker alive");
            "panicked"
        } else {
            s.inject_sim_device_loss().expect("worker alive");
            "device has been lost"
        };
        let started = std::time::Instant::now();
        // Throughput may still take one finished job; within two frames the error comes.
        let errors: Vec<_> = (0..2).map(|_| frame(&render, &mut s)).collect();
        assert!(
            errors.iter().any(|e| matches!(e, Err(Error::SimulationStopped(m)) if m.contains(expected))),
            "{errors:?}"
        );
        // And it stays an error, not a hang or a panic.
        assert!(matches!(frame(&render, &mut s), Err(Error::SimulationStopped(_))));
        assert!(matches!(s.read_state(), Err(Error::SimulationStopped(_))));
        assert!(started.elapsed() < Duration::from_secs(15));
        drop(s);
    }
    assert!(render.finish_with_messages().is_empty());
    assert!(sim.finish_with_messages().is_empty());
}

/// A worker that is alive but stuck: the next frame call gives a hand-off
/// error at the scheduler's timeout, not a hang.
#[test]
fn a_stuck_worker_meets_the_deadline() {
    let render = TestGpu::new();
    let sim = TestGpu::new();
    let timeout = Duration::from_millis(500);
    let mut s = remote(&render, &sim, Pipelining::Latency, timeout);
    frame(&render, &mut s).expect("first frame");
    s.inject_worker_stall(Duration::from_secs(3)).expect("worker alive");
    let started = std::time::Instant::now();
    let result = frame(&render, &mut s);
    let waited = started.elapsed();
    assert!(matches!(result, Err(Error::HandOff(_))), "{result:?}");
    assert!(waited >= timeout && waited < 4 * timeout, "the frame call waited {waited:?} for a {timeout:?} deadline");
    drop(s);
    assert!(render.finish_with_messages().is_empty());
    assert!(sim.finish_with_messages().is_empty());
}

/// A level of detail set on a SECOND DEVICE scheduler reaches its worker: the
/// count is checked on the host (0 and past the key hairs refused there), and
/// frames run with it.
#[test]
fn a_level_of_detail_reaches_the_worker() {
    let (render, sim) = (TestGpu::new(), TestGpu::new());
    let mut s = remote(&render, &sim, Pipelining::Throughput, Duration::from_secs(30));
    for bad in [0, 9] {
        let e = s.set_simulated_hairs(bad).expect_err("refused").to_string();
        assert!(e.contains("simulated key hairs") && e.contains("1..=8"), "{e}");
    }
    s.set_simulated_hairs(3).expect("level");
    for _ in 0..3 {
        frame(&render, &mut s).expect("frame");
    }
    let state = s.read_state().expect("state");
    assert!(state.positions.iter().all(|p| p.is_finite()), "{state:?}");
    drop(s);
    assert!(render.finish_with_messages().is_empty());
    assert!(sim.finish_with_messages().is_empty());
}
