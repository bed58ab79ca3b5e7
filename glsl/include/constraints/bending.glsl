// Bending constraints (with SIM_BENDING): points c − 1 and c + 1 held at their
// rest distance, with a stiffness per iteration from sim_bending_root at the
// root to sim_bending_tip at the tip; set 0 the centres c with c mod 4 in
// {0, 1}, set 1 those in {2, 3}. Twin: src/sim/reference/constraints/bending.rs.

// Per set: the partner's offset (0: none), whether own is the pair's first
// point, the rest distance and the stiffness.
int bending_offset[2] = int[2](0, 0);
bool bending_first[2] = bool[2](false, false);
vec2 bending_rest_k[2] = vec2[2](vec2(0.0), vec2(0.0));

// Rest distance and stiffness of the constraint centred on point c of the hair
// whose first point is at strand_base.
vec2 bending_at(uint strand_base, uint c, uint points) {
    precise vec3 r = rest[strand_base + c + 1u].xyz - rest[strand_base + c - 1u].xyz;
    precise float t = float(c) / float(points - 1u);
    precise float k = sim_bending_root(params) + (sim_bending_tip(params) - sim_bending_root(params)) * t;
    return vec2(sqrt(dot(r, r)), k);
}

void bending_load(uint i, uint points, uint index) {
    if ((step_flags() & SIM_BENDING) == 0u) {
        return;
    }
    uint base = index - i;
    if (i + 2u < points) {
        uint c = i + 1u;
        vec2 bk = bending_at(base, c, points);
        // Constant indices only: an array written at a computed index may
        // live in memory rather than registers.
        if (bk.y > 0.0 && (c & 3u) < 2u) {
            bending_offset[0] = 2; bending_first[0] = true; bending_rest_k[0] = bk;
        } else if (bk.y > 0.0) {
            bending_offset[1] = 2; bending_first[1] = true; bending_rest_k[1] = bk;
        }
    }
    if (i >= 2u) {
        uint c = i - 1u;
        vec2 bk = bending_at(base, c, points);
        if (bk.y > 0.0 && (c & 3u) < 2u) {
            bending_offset[0] = -2; bending_rest_k[0] = bk;
        } else if (bk.y > 0.0) {
            bending_offset[1] = -2; bending_rest_k[1] = bk;
        }
    }
}

bool bending_on(uint it) {
    return (step_flags() & SIM_BENDING) != 0u;
}

vec4 bending_apply(uint set, vec4 own, uint lid, uint src) {
    return set == 0u ? constraint_project_end(own, lid, bending_offset[0], bending_first[0], bending_rest_k[0].x,
                                              bending_rest_k[0].y, src)
                     : constraint_project_end(own, lid, bending_offset[1], bending_first[1], bending_rest_k[1].x,
                                              bending_rest_k[1].y, src);
}
