// Sampling the mesh collider's field (src/sim/mesh_collider.rs) in a
// simulation stage. The including shader declares, before the #include,
//     layout(std430, ...) readonly buffer MeshField { float mesh_field[]; };
// With VKHAIR_MESH_SKIN defined it also declares
//     layout(std430, ...) readonly buffer MeshSkin { uint mesh_skin[]; };
//     layout(std430, ...) readonly buffer MeshBones { vec4 mesh_bones[]; };
// for a field that follows bones (`mesh_collide_skinned`).
// The CPU twins are `mesh_sample` and `mesh_collide` in src/sim/reference/bodies.rs
// (and `skin.rs` beside it for the skinned field).
#ifndef VKHAIR_MESH_SDF_GLSL
#define VKHAIR_MESH_SDF_GLSL

// Where the field's samples are: grid point (0, 0, 0) in the head frame, the
// edge of one cell and the grid points per axis (a stage builds it from its
// parameter block's accessors, e.g. `sim_mesh_origin(p)`).
struct MeshGrid {
    vec3 origin;
    float cell;
    uvec3 points;
};

// Trilinear field value (w) and the gradient of the same interpolant (xyz,
// per cell, unnormalised) at q in the head frame. Outside the grid (which
// reaches at least two cells past the mesh) w is +1e30: no contact.
vec4 mesh_sample(MeshGrid m, vec3 q) {
    uvec3 dims = m.points;
    precise vec3 g = (q - m.origin) / m.cell;
    vec3 top = vec3(dims) - 1.0;
    if (any(lessThan(g, vec3(0.0))) || any(greaterThan(g, top))) {
        return vec4(0.0, 0.0, 0.0, 1e30);
    }
    vec3 base = min(floor(g), top - 1.0);
    precise vec3 f = g - base;
    uvec3 b = uvec3(base);
    uint sx = 1u;
    uint sy = dims.x;
    uint sz = dims.x * dims.y;
    uint k = (b.z * dims.y + b.y) * dims.x + b.x;
    float c000 = mesh_field[k];
    float c100 = mesh_field[k + sx];
    float c010 = mesh_field[k + sy];
    float c110 = mesh_field[k + sx + sy];
    float c001 = mesh_field[k + sz];
    float c101 = mesh_field[k + sx + sz];
    float c011 = mesh_field[k + sy + sz];
    float c111 = mesh_field[k + sx + sy + sz];
    precise float x00 = c000 + (c100 - c000) * f.x;
    precise float x10 = c010 + (c110 - c010) * f.x;
    precise float x01 = c001 + (c101 - c001) * f.x;
    precise float x11 = c011 + (c111 - c011) * f.x;
    precise float y0 = x00 + (x10 - x00) * f.y;
    precise float y1 = x01 + (x11 - x01) * f.y;
    precise float value = y0 + (y1 - y0) * f.z;
    precise float gx0 = (c100 - c000) + ((c110 - c010) - (c100 - c000)) * f.y;
    precise float gx1 = (c101 - c001) + ((c111 - c011) - (c101 - c001)) * f.y;
    precise float gx = gx0 + (gx1 - gx0) * f.z;
    precise float gy = (x10 - x00) + ((x11 - x01) - (x10 - x00)) * f.z;
    precise float gz = y1 - y0;
    return vec4(gx, gy, gz, value);
}

// q (in the field's frame) pushed out along the field's gradient to a gap of
// `radius`; `pushed` false (and q kept) where it keeps that gap already or the
// gradient vanishes.
vec3 mesh_push(MeshGrid m, vec3 q, float radius, out bool pushed) {
    vec4 s = mesh_sample(m, q);
    pushed = false;
    if (s.w < radius) {
        precise float len = sqrt(sim_dot(s.xyz, s.xyz));
        if (len > 0.0) {
            pushed = true;
            precise vec3 out_q = q + s.xyz * ((radius - s.w) / len);
            return out_q;
        }
    }
    return q;
}

// Friction in the field's frame: q, within `radius` plus a tenth of a cell of
// the surface, loses the fraction `friction` of its motion along the surface
// since `from_q`; `held` false (and q kept) where it does not touch.
vec3 mesh_hold(MeshGrid m, vec3 q, vec3 from_q, float radius, float friction, out bool held) {
    vec4 s = mesh_sample(m, q);
    precise float contact = radius + 0.1 * m.cell;
    precise float len = sqrt(sim_dot(s.xyz, s.xyz));
    held = s.w < contact && len > 0.0 && friction > 0.0;
    if (!held) {
        return q;
    }
    precise vec3 n = s.xyz / len;
    precise vec3 moved = q - from_q;
    precise vec3 along = moved - n * sim_dot(n, moved);
    precise vec3 kept = q - along * friction;
    return kept;
}

// Projects world point p out of the mesh (moved by `head`) along the field's
// gradient, keeping a gap of `radius`.
vec3 mesh_collide(mat4 head, MeshGrid m, vec3 p, float radius) {
    bool pushed;
    precise vec3 q = mesh_push(m, sim_to_head(head, p), radius, pushed);
    return pushed ? sim_transform_point(head, q) : p;
}

// Friction with the mesh: a particle within `radius` plus a tenth of a cell of
// the surface loses the fraction `friction` of its motion along the surface
// relative to the mesh during the step (`from` is where it was, the mesh then
// placed by `previous_head`).
vec3 mesh_friction(mat4 head, mat4 previous_head, MeshGrid m, vec3 p, vec3 from, float radius, float friction) {
    bool held;
    precise vec3 q = mesh_hold(m, sim_to_head(head, p), sim_to_head(previous_head, from), radius, friction, held);
    return held ? sim_transform_point(head, q) : p;
}

#ifdef VKHAIR_MESH_SKIN
// A skinned field (src/sim/mesh_skin.rs): every grid point names two bones and
// the first one's weight (`mesh_skin`: bone 0 in bits 0-7, bone 1 in 8-15, the
// weight in 16-31 as a 16-bit fraction); each sub-step's bones are the rows
// of their 3×4 matrices (bind pose, head frame → world), six vec4 per bone in
// `mesh_bones` from the sub-step's base: three at the end of the sub-step,
// three at its start. A point is taken to the bind pose by the blend of its
// grid point's bones, measured there, and moved back by the same blend.

// The rows of a 3×4 matrix (the fourth column in w).
struct MeshRows {
    vec4 r0;
    vec4 r1;
    vec4 r2;
};

// Entry of sub-step `sub`'s bones in `mesh_bones`.
uint mesh_bone_base(uint sub) {
    return sub * SIM_MESH_MAX_BONES * 6u;
}

// The grid point nearest q, clamped into the grid (a NaN lane: the first).
uint mesh_nearest_point(MeshGrid m, vec3 q) {
    precise vec3 g = floor((q - m.origin) / m.cell + 0.5);
    vec3 top = vec3(m.points) - 1.0;
    uvec3 b;
    for (int a = 0; a < 3; a++) {
        float v = g[a] >= 0.0 ? g[a] : 0.0;
        b[a] = uint(v <= top[a] ? v : top[a]);
    }
    return (b.z * m.points.y + b.y) * m.points.x + b.x;
}

// The blend of grid point word `word`'s two bones from `base`, at the end of
// the sub-step (`start` 0) or at its start (`start` 3).
MeshRows mesh_skin_rows(uint word, uint base, uint start) {
    uint a = base + (word & 0xFFu) * 6u + start;
    uint b = base + ((word >> 8) & 0xFFu) * 6u + start;
    precise float w0 = float(word >> 16) / 65535.0;
    precise float w1 = 1.0 - w0;
    MeshRows r;
    precise vec4 r0 = mesh_bones[a] * w0 + mesh_bones[b] * w1;
    precise vec4 r1 = mesh_bones[a + 1u] * w0 + mesh_bones[b + 1u] * w1;
    precise vec4 r2 = mesh_bones[a + 2u] * w0 + mesh_bones[b + 2u] * w1;
    r.r0 = r0;
    r.r1 = r1;
    r.r2 = r2;
    return r;
}

// m applied to q.
vec3 mesh_rows_apply(MeshRows m, vec3 q) {
    precise float x = ((m.r0.x * q.x + m.r0.y * q.y) + m.r0.z * q.z) + m.r0.w;
    precise float y = ((m.r1.x * q.x + m.r1.y * q.y) + m.r1.z * q.z) + m.r1.w;
    precise float z = ((m.r2.x * q.x + m.r2.y * q.y) + m.r2.z * q.z) + m.r2.w;
    return vec3(x, y, z);
}

vec3 mesh_cross(vec3 a, vec3 b) {
    precise vec3 c = vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
    return c;
}

// The point m takes to p (by the adjugate); far outside every grid (1e30)
// when m does not invert (a determinant of magnitude under 1e-12).
vec3 mesh_rows_invert(MeshRows m, vec3 p) {
    precise vec3 d = p - vec3(m.r0.w, m.r1.w, m.r2.w);
    precise vec3 c0 = mesh_cross(m.r1.xyz, m.r2.xyz);
    precise vec3 c1 = mesh_cross(m.r2.xyz, m.r0.xyz);
    precise vec3 c2 = mesh_cross(m.r0.xyz, m.r1.xyz);
    precise float det = (m.r0.x * c0.x + m.r0.y * c0.y) + m.r0.z * c0.z;
    if (!(abs(det) > 1e-12)) {
        return vec3(1e30);
    }
    precise vec3 q = ((c0 * d.x + c1 * d.y) + c2 * d.z) / det;
    return q;
}

// The skin word of world point p: looked up at p taken to the head frame by
// `head`, then again at p taken to the bind pose by that word's bones.
uint mesh_point_word(mat4 head, MeshGrid m, uint base, vec3 p) {
    uint word = mesh_skin[mesh_nearest_point(m, sim_to_head(head, p))];
    precise vec3 q = mesh_rows_invert(mesh_skin_rows(word, base, 0u), p);
    return mesh_skin[mesh_nearest_point(m, q)];
}

// mesh_collide for a skinned field (bones of the sub-step from `base`).
vec3 mesh_collide_skinned(mat4 head, MeshGrid m, uint base, vec3 p, float radius) {
    MeshRows r = mesh_skin_rows(mesh_point_word(head, m, base, p), base, 0u);
    bool pushed;
    precise vec3 q = mesh_push(m, mesh_rows_invert(r, p), radius, pushed);
    return pushed ? mesh_rows_apply(r, q) : p;
}

// mesh_friction for a skinned field: the motion relative to the surface is
// measured in the bind pose, `from` taken there by the sub-step's start bones.
vec3 mesh_friction_skinned(mat4 head, MeshGrid m, uint base, vec3 p, vec3 from, float radius, float friction) {
    uint word = mesh_point_word(head, m, base, p);
    MeshRows r = mesh_skin_rows(word, base, 0u);
    precise vec3 from_q = mesh_rows_invert(mesh_skin_rows(word, base, 3u), from);
    bool held;
    precise vec3 q = mesh_hold(m, mesh_rows_invert(r, p), from_q, radius, friction, held);
    return held ? mesh_rows_apply(r, q) : p;
}
#endif

#endif
