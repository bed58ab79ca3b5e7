// Sampling the mesh collider's field (src/sim/mesh_collider.rs) in a
// simulation stage. The including shader declares, before the #include,
//     layout(std430, ...) readonly buffer MeshField { float mesh_field[]; };
// The CPU twins are `mesh_sample` and `mesh_collide` in src/sim/reference/bodies.rs.
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

// Projects world point p out of the mesh (moved by `head`) along the field's
// gradient, keeping a gap of `radius`.
vec3 mesh_collide(mat4 head, MeshGrid m, vec3 p, float radius) {
    precise vec3 q = sim_to_head(head, p);
    vec4 s = mesh_sample(m, q);
    if (s.w < radius) {
        precise float len = sqrt(sim_dot(s.xyz, s.xyz));
        if (len > 0.0) {
            precise vec3 out_q = q + s.xyz * ((radius - s.w) / len);
            return sim_transform_point(head, out_q);
        }
    }
    return p;
}

// Friction with the mesh: a particle within `radius` plus a tenth of a cell of
// the surface loses the fraction `friction` of its motion along the surface
// relative to the mesh during the step (`from` is where it was, the mesh then
// placed by `previous_head`).
vec3 mesh_friction(mat4 head, mat4 previous_head, MeshGrid m, vec3 p, vec3 from, float radius, float friction) {
    precise vec3 q = sim_to_head(head, p);
    vec4 s = mesh_sample(m, q);
    precise float contact = radius + 0.1 * m.cell;
    precise float len = sqrt(sim_dot(s.xyz, s.xyz));
    if (!(s.w < contact) || !(len > 0.0) || friction <= 0.0) {
        return p;
    }
    precise vec3 n = s.xyz / len;
    precise vec3 moved = q - sim_to_head(previous_head, from);
    precise vec3 along = moved - n * sim_dot(n, moved);
    precise vec3 held = q - along * friction;
    return sim_transform_point(head, held);
}

#endif
