//! `vkhair render` at every size in its default mode (exact transparency): the
//! fragment pool is split over several buffers where one binding's range is too
//! small (128 MiB on lavapipe), and where even those cannot hold the request the
//! tool says what it did and renders with the pool the device holds.

use crate::common;

use std::time::Duration;

use common::run;

const LIMIT: Duration = Duration::from_secs(300);

#[test]
fn full_hd_and_4k_render_in_the_default_mode_and_a_capped_pool_is_reported() {
    let dir = tempfile::tempdir().expect("temp dir");
    let groom = dir.path().join("cap.hair");
    common::write_groom(&groom, &common::cap_groom(60, 8, 0.1));
    let g = groom.to_str().expect("utf-8");
    let config = dir.path().join("pool.toml");
    std::fs::write(&config, "[render.oit]\nfragments_per_pixel = 16\n").expect("config");
    let c = config.to_str().expect("utf-8");
    // On any device: pool buffers of 64 KiB hold 8 × 4,096 of the 16.6 M nodes 1080p asks for.
    let small = dir.path().join("small.toml");
    std::fs::write(&small, "[render.oit]\nmax_buffer_bytes = 65536\n").expect("config");
    let sm = small.to_str().expect("utf-8");
    let cases: [(u32, u32, Option<&str>); 4] =
        [(1920, 1080, None), (3840, 2160, None), (3840, 2160, Some(c)), (1920, 1080, Some(sm))];
    for (w, h, config) in cases {
        let out = dir.path().join(format!("{w}x{h}{}", if config.is_some() { "-16" } else { "" }));
        let (ws, hs, o) = (w.to_string(), h.to_string(), out.display().to_string());
        // A tenth of a scalp's hairs: the pool's size follows the pixels.
        let mut args = vec![
            "render",
            "--input",
            g,
            "--density",
            "15",
            "--frames",
            "1",
            "--width",
            &ws,
            "--height",
            &hs,
            "--out",
            &o,
        ];
        if let Some(c) = config {
            args.extend(["--config", c]);
        }
        let r = run(&args, LIMIT);
        r.assert_ok();
        assert!(r.stdout.contains("transparency: Exact"), "not the exact mode: {}", r.stdout);
        let (pw, ph, rgba) = common::read_png(&out.join("frame_0000.png"));
        assert_eq!((pw, ph), (w, h));
        let cover = common::coverage(&rgba);
        println!("{w}×{h} (config {config:?}): {:.2} % hair\n{}", cover * 100.0, r.stderr);
        assert!(cover > 0.005, "no hair at {w}×{h}");
        let capped = r.stderr.contains(&format!("warning: at {w}×{h} this device holds"));
        // lavapipe: 8 buffers of 128 MiB hold 8 fragments per pixel at 4K, not 16.
        let small_buffers = r.stdout.contains("llvmpipe");
        match config {
            Some(path) if path == sm => {
                assert!(capped, "the capped pool went unreported: {}", r.stderr);
                assert!(r.stderr.contains("holds 0.02 of the 8 fragments per pixel"), "{}", r.stderr);
            }
            Some(_) if small_buffers => {
                assert!(capped, "the capped pool went unreported: {}", r.stderr);
                assert!(r.stderr.contains("join the order-independent tail"), "{}", r.stderr);
            }
            Some(_) => println!("skipped the capped-pool check: this device holds 16 fragments per pixel at 4K"),
            None => assert!(!capped, "the default pool was capped at {w}×{h}: {}", r.stderr),
        }
    }
}
