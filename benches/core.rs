//! Groom I/O and preparation on the CPU: `.hair` parse/write, growth and
//! resampling of the `thesis` scene and of a 10,000 × 32 groom.
//!
//! Each group has a baseline in the same run — copying the same number of
//! bytes (`memcpy`) — so figures can be read as ratios.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::grow::{grow, GrowParams};
use vkhair::groom::scenes;

fn hair_io(c: &mut Criterion) {
    let thesis = scenes::thesis().expect("thesis");
    let big =
        grow(&scenes::thesis_scalp(), &GrowParams { strands: 10_000, points_per_strand: 32, ..GrowParams::default() })
            .expect("big");
    for (name, groom) in [("thesis 1750x6", thesis), ("10000x32", big)] {
        let bytes = HairFile::new(groom.clone(), name).to_bytes();
        let mut g = c.benchmark_group(format!("hair io {name}"));
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function("baseline memcpy", |b| b.iter(|| black_box(bytes.clone())));
        g.bench_function("parse", |b| b.iter(|| HairFile::parse(black_box(&bytes)).expect("parse")));
        let file = HairFile::parse(&bytes).expect("parse");
        g.bench_function("write", |b| b.iter(|| black_box(&file).to_bytes()));
        g.bench_function("resample to 16", |b| b.iter(|| black_box(&groom).resampled(16).expect("resample")));
        g.finish();
    }
}

fn growth(c: &mut Criterion) {
    let mut g = c.benchmark_group("growth");
    g.bench_function("thesis scene", |b| b.iter(|| scenes::thesis().expect("thesis")));
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = hair_io, growth
}
criterion_main!(benches);
