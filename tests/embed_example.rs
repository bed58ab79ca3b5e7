//! Runs `examples/embed_minimal/` — a host with its own instance, device,
//! allocator, images, pipeline and head mesh embedding vkhair through
//! `GpuContext::from_host` — under validation, and checks what it drew.

#[path = "../examples/embed_minimal/main.rs"]
mod embed;

#[test]
fn the_embedding_example_draws_hair_over_its_head_without_validation_messages() {
    let outcome = embed::run(3, true).expect("the example runs");
    assert!(outcome.validation_messages.is_empty(), "validation: {:#?}", outcome.validation_messages);
    let (hair, head) = embed::classify(&outcome.pixels);
    eprintln!("hair pixels {hair}, head pixels {head}\n{}", outcome.timings);
    // 256×192 = 49,152 pixels: the head and the hair each take a good share.
    assert!(hair > 3000, "too little hair drawn: {hair}");
    assert!(head > 1000, "the host's head is hidden or missing: {head}");
    assert!(outcome.timings.contains("vkhair render: draw"), "per-pass timings reach the host: {}", outcome.timings);
}
