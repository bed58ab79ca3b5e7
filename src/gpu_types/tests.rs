//! The views against the shaders' accessors: a generated compute shader
//! (`generated/views_probe.comp`) reads a block of distinct words per view and
//! writes every accessor's value back, then every shared code; the Rust side's
//! `From<&Block>` conversion of the same block, and the crate's constants,
//! must give the same words. A lane swapped on either side (build.rs's
//! accessor generator, the crate's view macros) or a code that differs fails.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::codes::SHADER_CODES;
use crate::vk::buffer::Buffer;
use crate::vk::pipeline::ComputePipeline;
use crate::vk::shaders;
use crate::vk::tests::TestGpu;

/// One view: its block's bytes and the words the probe must write for them.
pub(crate) struct ProbeCase {
    pub view: &'static str,
    pub bytes: Vec<u8>,
    pub words: Vec<u32>,
}

/// A block whose every 32-bit word differs from every other block's and its
/// own (as a float, 1000·seed + index + ¼: finite, exact, never zero).
pub(crate) fn distinct_words<T: Pod + Zeroable>(seed: u32) -> T {
    let mut block = T::zeroed();
    for (i, word) in bytemuck::cast_slice_mut::<u8, u32>(bytemuck::bytes_of_mut(&mut block)).iter_mut().enumerate() {
        *word = (1000.0 * seed as f32 + i as f32 + 0.25).to_bits();
    }
    block
}

/// A view field as the probe writes it: 32-bit words, floats as their bits,
/// matrices column by column.
pub(crate) trait ProbeWords {
    fn probe_words(&self) -> Vec<u32>;
}

impl ProbeWords for f32 {
    fn probe_words(&self) -> Vec<u32> {
        vec![self.to_bits()]
    }
}

impl ProbeWords for u32 {
    fn probe_words(&self) -> Vec<u32> {
        vec![*self]
    }
}

impl ProbeWords for Vec3 {
    fn probe_words(&self) -> Vec<u32> {
        self.to_array().map(f32::to_bits).to_vec()
    }
}

impl ProbeWords for [u32; 3] {
    fn probe_words(&self) -> Vec<u32> {
        self.to_vec()
    }
}

impl ProbeWords for super::SimKnobs {
    fn probe_words(&self) -> Vec<u32> {
        self.values().into_iter().map(f32::to_bits).collect()
    }
}

impl ProbeWords for Mat4 {
    fn probe_words(&self) -> Vec<u32> {
        self.to_cols_array().map(f32::to_bits).to_vec()
    }
}

#[test]
fn every_view_and_code_reads_the_same_in_the_shaders() {
    let gpu = TestGpu::new();
    let d = gpu.device();
    let cases = super::probe_cases();
    let pipeline = ComputePipeline::new(d, &shaders::GENERATED_VIEWS_PROBE_COMP, 1).expect("pipeline");
    let blocks: Vec<Buffer> = cases
        .iter()
        .map(|case| {
            let buffer = Buffer::storage(d, case.view, case.bytes.len() as u64).expect("buffer");
            d.upload(&buffer, 0, &case.bytes).expect("upload");
            buffer
        })
        .collect();
    let expected: Vec<u32> =
        cases.iter().flat_map(|c| c.words.iter().copied()).chain(SHADER_CODES.iter().map(|(_, v)| *v)).collect();
    let words = Buffer::storage(d, "probe words", 4 * expected.len() as u64 + 64).expect("buffer");
    d.upload_pod(&words, &vec![0xdead_beef_u32; expected.len() + 16]).expect("upload");
    let mut bindings: Vec<(u32, &Buffer)> = blocks.iter().enumerate().map(|(i, b)| (i as u32, b)).collect();
    bindings.push((cases.len() as u32, &words));
    let set = pipeline.buffer_set(0, &bindings).expect("set");
    d.submit_once("views probe", |cmd| {
        // SAFETY: a recording command buffer of this device; the buffers are this device's.
        unsafe {
            pipeline.bind(cmd, &[set]);
            pipeline.dispatch_threads(cmd, [1, 1, 1]);
        }
    })
    .expect("submit");
    let got: Vec<u32> = d.readback_pod(&words, expected.len() + 16).expect("readback");
    let mut at = 0;
    for case in &cases {
        let n = case.words.len();
        assert_eq!(got[at..at + n], case.words, "{}: the shaders' accessors read other lanes than the view", case.view);
        at += n;
    }
    for (name, value) in SHADER_CODES {
        assert_eq!(got[at], *value, "{name}: the shaders see {} where the crate has {value}", got[at]);
        at += 1;
    }
    assert!(got[at..].iter().all(|&w| w == 0xdead_beef), "the probe wrote past the expected words");
    assert!(cases.len() >= 11 && at > 150, "the probe covered only {} views, {at} words", cases.len());
}
