//! SPIR-V reflection with rspirv: descriptor bindings, push-constant block,
//! workgroup size and the layout (member offsets and sizes) of every struct,
//! compared against the Rust `#[repr(C)]` twins in [`crate::gpu_types`].

use std::collections::HashMap;

use ash::vk;
use rspirv::dr::{Instruction, Operand};
use rspirv::spirv::{Decoration, Dim, ExecutionMode, ExecutionModel, Op, StorageClass};

use super::shaders::ShaderSource;
use crate::error::{Error, Result};

/// One member of a reflected struct.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Member {
    pub name: String,
    pub offset: u32,
    /// Size in bytes (0 for a runtime array).
    pub size: u32,
}

/// The layout of a struct as the shader uses it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct StructLayout {
    pub name: String,
    pub members: Vec<Member>,
    /// Array strides of every array of this struct in the module.
    pub array_strides: Vec<u32>,
}

impl StructLayout {
    /// Bytes from the first member's offset to the end of the last member.
    pub(crate) fn span(&self) -> u32 {
        self.members.iter().map(|m| m.offset + m.size).max().unwrap_or(0)
    }
}

/// One descriptor binding.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Binding {
    pub set: u32,
    pub binding: u32,
    pub ty: vk::DescriptorType,
    pub count: u32,
    pub name: String,
    /// Whether the shader may read the binding (not `NonReadable`).
    pub reads: bool,
    /// Whether the shader may write it (a storage buffer or image not `NonWritable`).
    pub writes: bool,
}

/// What a shader module declares.
#[derive(Debug, Clone)]
pub(crate) struct Reflection {
    pub stage: vk::ShaderStageFlags,
    pub workgroup_size: Option<[u32; 3]>,
    pub bindings: Vec<Binding>,
    /// Byte size of the push-constant block (0 when none).
    pub push_constant_size: u32,
    /// Read by the layout tests, which compare them with the Rust twins.
    #[cfg_attr(not(test), allow(dead_code))]
    pub structs: Vec<StructLayout>,
}

impl Reflection {
    #[cfg(test)]
    /// Every layout of the struct named `name` (a struct used under two layout
    /// rules appears twice).
    pub(crate) fn structs_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a StructLayout> + 'a {
        self.structs.iter().filter(move |s| s.name == name)
    }
}

/// Decorations of one target: the decoration and its extra operands.
type Decorations = Vec<(Decoration, Vec<Operand>)>;

struct Module {
    names: HashMap<u32, String>,
    member_names: HashMap<(u32, u32), String>,
    decorations: HashMap<u32, Decorations>,
    member_decorations: HashMap<(u32, u32), Decorations>,
    defs: HashMap<u32, Instruction>,
}

fn id(op: Option<&Operand>) -> Option<u32> {
    match op {
        Some(Operand::IdRef(i)) => Some(*i),
        _ => None,
    }
}

fn lit(op: Option<&Operand>) -> Option<u32> {
    match op {
        Some(Operand::LiteralBit32(v)) => Some(*v),
        _ => None,
    }
}

impl Module {
    fn decoration(&self, target: u32, which: Decoration) -> Option<&[Operand]> {
        self.decorations.get(&target)?.iter().find(|(d, _)| *d == which).map(|(_, o)| o.as_slice())
    }

    fn member_decoration(&self, target: u32, member: u32, which: Decoration) -> Option<&[Operand]> {
        self.member_decorations.get(&(target, member))?.iter().find(|(d, _)| *d == which).map(|(_, o)| o.as_slice())
    }

    /// Whether variable `var` of block (or image) type `element` is read and
    /// written: `NonReadable`/`NonWritable` on the variable or on every member of
    /// its block; only storage buffers and images are written.
    fn access(&self, var: u32, element: u32, ty: vk::DescriptorType) -> (bool, bool) {
        let members =
            self.defs.get(&element).filter(|d| d.class.opcode == Op::TypeStruct).map_or(0, |d| d.operands.len());
        let has = |which: Decoration| {
            self.decoration(var, which).is_some()
                || (members > 0 && (0..members as u32).all(|i| self.member_decoration(element, i, which).is_some()))
        };
        let writable = matches!(ty, vk::DescriptorType::STORAGE_BUFFER | vk::DescriptorType::STORAGE_IMAGE);
        (!has(Decoration::NonReadable), writable && !has(Decoration::NonWritable))
    }

    fn constant(&self, id: u32) -> Option<u32> {
        let def = self.defs.get(&id)?;
        (def.class.opcode == Op::Constant).then(|| lit(def.operands.first())).flatten()
    }

    /// Size of type `ty` inside a block; `matrix_stride` applies to matrices.
    fn size_of(&self, ty: u32, matrix_stride: Option<u32>) -> Option<u32> {
        let def = self.defs.get(&ty)?;
        let ops = &def.operands;
        Some(match def.class.opcode {
            Op::TypeInt | Op::TypeFloat => lit(ops.first())? / 8,
            Op::TypeBool => 4,
            Op::TypeVector => lit(ops.get(1))? * self.size_of(id(ops.first())?, None)?,
            Op::TypeMatrix => {
                let columns = lit(ops.get(1))?;
                match matrix_stride {
                    Some(stride) => columns * stride,
                    None => columns * self.size_of(id(ops.first())?, None)?,
                }
            }
            Op::TypeArray => {
                let length = self.constant(id(ops.get(1))?)?;
                let stride = match self.decoration(ty, Decoration::ArrayStride) {
                    Some(o) => lit(o.first())?,
                    None => self.size_of(id(ops.first())?, None)?,
                };
                length * stride
            }
            Op::TypeRuntimeArray => 0,
            Op::TypeStruct => self.struct_layout(ty)?.span(),
            _ => return None,
        })
    }

    fn struct_layout(&self, ty: u32) -> Option<StructLayout> {
        let def = self.defs.get(&ty)?;
        if def.class.opcode != Op::TypeStruct {
            return None;
        }
        let mut members = Vec::new();
        for (i, op) in def.operands.iter().enumerate() {
            let i = i as u32;
            let member_ty = id(Some(op))?;
            let offset = lit(self.member_decoration(ty, i, Decoration::Offset)?.first())?;
            let stride = self.member_decoration(ty, i, Decoration::MatrixStride).and_then(|o| lit(o.first()));
            members.push(Member {
                name: self.member_names.get(&(ty, i)).cloned().unwrap_or_default(),
                offset,
                size: self.size_of(member_ty, stride)?,
            });
        }
        let array_strides = self
            .defs
            .values()
            .filter(|d| {
                matches!(d.class.opcode, Op::TypeArray | Op::TypeRuntimeArray) && id(d.operands.first()) == Some(ty)
            })
            .filter_map(|d| self.decoration(d.result_id?, Decoration::ArrayStride).and_then(|o| lit(o.first())))
            .collect();
        Some(StructLayout { name: self.names.get(&ty).cloned().unwrap_or_default(), members, array_strides })
    }

    fn descriptor_type(&self, pointee: u32, storage: StorageClass) -> Option<vk::DescriptorType> {
        let def = self.defs.get(&pointee)?;
        Some(match (storage, def.class.opcode) {
            (StorageClass::StorageBuffer, _) => vk::DescriptorType::STORAGE_BUFFER,
            (StorageClass::Uniform, _) if self.decoration(pointee, Decoration::BufferBlock).is_some() => {
                vk::DescriptorType::STORAGE_BUFFER
            }
            (StorageClass::Uniform, _) => vk::DescriptorType::UNIFORM_BUFFER,
            (StorageClass::UniformConstant, Op::TypeSampledImage) => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            (StorageClass::UniformConstant, Op::TypeSampler) => vk::DescriptorType::SAMPLER,
            (StorageClass::UniformConstant, Op::TypeImage) => {
                let buffer = matches!(def.operands.get(1), Some(Operand::Dim(Dim::DimBuffer)));
                let storage = lit(def.operands.get(5)) == Some(2);
                match (buffer, storage) {
                    (true, true) => vk::DescriptorType::STORAGE_TEXEL_BUFFER,
                    (true, false) => vk::DescriptorType::UNIFORM_TEXEL_BUFFER,
                    (false, true) => vk::DescriptorType::STORAGE_IMAGE,
                    (false, false) => vk::DescriptorType::SAMPLED_IMAGE,
                }
            }
            _ => return None,
        })
    }
}

fn stage_of(model: ExecutionModel) -> Option<vk::ShaderStageFlags> {
    Some(match model {
        ExecutionModel::GLCompute => vk::ShaderStageFlags::COMPUTE,
        ExecutionModel::Vertex => vk::ShaderStageFlags::VERTEX,
        ExecutionModel::TessellationControl => vk::ShaderStageFlags::TESSELLATION_CONTROL,
        ExecutionModel::TessellationEvaluation => vk::ShaderStageFlags::TESSELLATION_EVALUATION,
        ExecutionModel::Fragment => vk::ShaderStageFlags::FRAGMENT,
        _ => return None,
    })
}

/// Reflects a compiled shader.
pub(crate) fn reflect(shader: &ShaderSource) -> Result<Reflection> {
    let fail = |reason: String| Error::Shader { shader: shader.name.to_owned(), reason };
    let module = rspirv::dr::load_words(shader.words).map_err(|e| fail(format!("SPIR-V could not be parsed: {e}")))?;
    let mut m = Module {
        names: HashMap::new(),
        member_names: HashMap::new(),
        decorations: HashMap::new(),
        member_decorations: HashMap::new(),
        defs: HashMap::new(),
    };
    for inst in &module.debug_names {
        match (inst.class.opcode, inst.operands.as_slice()) {
            (Op::Name, [Operand::IdRef(t), Operand::LiteralString(n)]) => {
                m.names.insert(*t, n.clone());
            }
            (Op::MemberName, [Operand::IdRef(t), Operand::LiteralBit32(i), Operand::LiteralString(n)]) => {
                m.member_names.insert((*t, *i), n.clone());
            }
            _ => {}
        }
    }
    for inst in &module.annotations {
        match (inst.class.opcode, inst.operands.as_slice()) {
            (Op::Decorate, [Operand::IdRef(t), Operand::Decoration(d), rest @ ..]) => {
                m.decorations.entry(*t).or_default().push((*d, rest.to_vec()));
            }
            (Op::MemberDecorate, [Operand::IdRef(t), Operand::LiteralBit32(i), Operand::Decoration(d), rest @ ..]) => {
                m.member_decorations.entry((*t, *i)).or_default().push((*d, rest.to_vec()));
            }
            _ => {}
        }
    }
    for inst in &module.types_global_values {
        if let Some(r) = inst.result_id {
            m.defs.insert(r, inst.clone());
        }
    }
    let [entry] = module.entry_points.as_slice() else {
        return Err(fail(format!("expected one entry point, found {}", module.entry_points.len())));
    };
    let stage = match entry.operands.first() {
        Some(Operand::ExecutionModel(model)) => stage_of(*model),
        _ => None,
    }
    .ok_or_else(|| fail("unsupported execution model".into()))?;
    let entry_id = id(entry.operands.get(1));
    let interface: Vec<u32> = entry.operands.iter().skip(3).filter_map(|o| id(Some(o))).collect();

    let mut workgroup_size = None;
    for inst in &module.execution_modes {
        if id(inst.operands.first()) != entry_id {
            continue;
        }
        match inst.operands.get(1) {
            Some(Operand::ExecutionMode(ExecutionMode::LocalSize)) => {
                let dims = [lit(inst.operands.get(2)), lit(inst.operands.get(3)), lit(inst.operands.get(4))];
                if let [Some(x), Some(y), Some(z)] = dims {
                    workgroup_size = Some([x, y, z]);
                }
            }
            Some(Operand::ExecutionMode(ExecutionMode::LocalSizeId)) => {
                return Err(fail("LocalSizeId is not supported: compile for SPIR-V 1.5".into()));
            }
            _ => {}
        }
    }
    if stage == vk::ShaderStageFlags::COMPUTE && workgroup_size.is_none() {
        return Err(fail("compute shader without LocalSize".into()));
    }

    let mut bindings = Vec::new();
    let mut push_constant_size = 0;
    for var in &interface {
        let Some(def) = m.defs.get(var) else { continue };
        if def.class.opcode != Op::Variable {
            continue;
        }
        let Some(Operand::StorageClass(storage)) = def.operands.first() else { continue };
        let storage = *storage;
        let pointee = def
            .result_type
            .and_then(|p| m.defs.get(&p))
            .and_then(|p| id(p.operands.get(1)))
            .ok_or_else(|| fail(format!("variable %{var} has no pointer type")))?;
        if storage == StorageClass::PushConstant {
            let layout = m
                .struct_layout(pointee)
                .ok_or_else(|| fail("push-constant block layout could not be reflected".into()))?;
            push_constant_size = layout.span();
            continue;
        }
        if !matches!(storage, StorageClass::Uniform | StorageClass::StorageBuffer | StorageClass::UniformConstant) {
            continue;
        }
        let (element, count) = match m.defs.get(&pointee).map(|d| (d.class.opcode, &d.operands)) {
            Some((Op::TypeArray, ops)) => {
                let count = id(ops.get(1))
                    .and_then(|c| m.constant(c))
                    .ok_or_else(|| fail("descriptor array without constant length".into()))?;
                (id(ops.first()).unwrap_or(pointee), count)
            }
            Some((Op::TypeRuntimeArray, _)) => return Err(fail("runtime descriptor arrays are not supported".into())),
            _ => (pointee, 1),
        };
        let ty = m
            .descriptor_type(element, storage)
            .ok_or_else(|| fail(format!("variable %{var}: unsupported descriptor type")))?;
        let set = m.decoration(*var, Decoration::DescriptorSet).and_then(|o| lit(o.first()));
        let binding = m.decoration(*var, Decoration::Binding).and_then(|o| lit(o.first()));
        let (Some(set), Some(binding)) = (set, binding) else {
            return Err(fail(format!("variable %{var} lacks set/binding decorations")));
        };
        let name =
            m.names.get(var).filter(|n| !n.is_empty()).or_else(|| m.names.get(&element)).cloned().unwrap_or_default();
        let (reads, writes) = m.access(*var, element, ty);
        bindings.push(Binding { set, binding, ty, count, name, reads, writes });
    }
    bindings.sort_by_key(|b| (b.set, b.binding));

    let mut structs: Vec<StructLayout> = m
        .defs
        .values()
        .filter(|d| d.class.opcode == Op::TypeStruct)
        .filter_map(|d| m.struct_layout(d.result_id?))
        .collect();
    structs.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(Reflection { stage, workgroup_size, bindings, push_constant_size, structs })
}

/// One field of a Rust GPU struct.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(test), allow(dead_code, reason = "compared with reflection by the layout tests"))]
pub(crate) struct FieldLayout {
    pub name: &'static str,
    pub offset: usize,
    pub size: usize,
}

/// A `#[repr(C)]` Pod struct with a GLSL twin of the same name in `glsl/include/`.
#[cfg_attr(not(test), allow(dead_code, reason = "compared with reflection by the layout tests"))]
pub(crate) trait GpuStruct: bytemuck::Pod {
    /// The GLSL struct name.
    const GLSL_NAME: &'static str;
    /// Every Rust field in declaration order.
    fn fields() -> Vec<FieldLayout>;
}

/// Compares a Rust struct with one reflected layout of its GLSL twin.
///
/// Rust fields named `_pad*` stand for implicit GLSL padding and are skipped;
/// every other field must match a GLSL member of the same name, in order, at the
/// same offset with the same size, and arrays of the struct must have a stride
/// equal to the Rust size.
#[cfg(test)]
pub(crate) fn compare<T: GpuStruct>(layout: &StructLayout) -> std::result::Result<(), String> {
    let rust: Vec<FieldLayout> = T::fields().into_iter().filter(|f| !f.name.starts_with("_pad")).collect();
    let mut problems = Vec::new();
    if rust.len() != layout.members.len() {
        problems.push(format!(
            "Rust has {} fields ({}) but GLSL has {} members ({})",
            rust.len(),
            rust.iter().map(|f| f.name).collect::<Vec<_>>().join(", "),
            layout.members.len(),
            layout.members.iter().map(|m| m.name.as_str()).collect::<Vec<_>>().join(", ")
        ));
    }
    for (r, g) in rust.iter().zip(&layout.members) {
        if r.name != g.name {
            problems.push(format!("field {} in Rust is {} in GLSL", r.name, g.name));
        }
        if r.offset != g.offset as usize {
            problems.push(format!("{}: Rust offset {} vs GLSL offset {}", r.name, r.offset, g.offset));
        }
        if g.size != 0 && r.size != g.size as usize {
            problems.push(format!("{}: Rust size {} vs GLSL size {}", r.name, r.size, g.size));
        }
    }
    let size = std::mem::size_of::<T>();
    for stride in &layout.array_strides {
        if *stride as usize != size {
            problems.push(format!("array stride {stride} in GLSL vs Rust size {size}"));
        }
    }
    if (layout.span() as usize) > size {
        problems.push(format!("GLSL span {} exceeds Rust size {size}", layout.span()));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!("{}: {}", T::GLSL_NAME, problems.join("; ")))
    }
}

/// Implements [`GpuStruct`] from the field list.
macro_rules! gpu_struct {
    ($ty:ty => $glsl:literal { $($field:ident),* $(,)? }) => {
        impl $crate::vk::reflect::GpuStruct for $ty {
            const GLSL_NAME: &'static str = $glsl;
            fn fields() -> Vec<$crate::vk::reflect::FieldLayout> {
                fn size_of_field<T, F>(_: fn(&T) -> &F) -> usize {
                    ::std::mem::size_of::<F>()
                }
                vec![$($crate::vk::reflect::FieldLayout {
                    name: stringify!($field),
                    offset: ::std::mem::offset_of!($ty, $field),
                    size: size_of_field::<$ty, _>(|s| &s.$field),
                }),*]
            }
        }
    };
}
pub(crate) use gpu_struct;
