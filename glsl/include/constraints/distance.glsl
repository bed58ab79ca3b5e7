// Distance constraints: each segment (j, j + 1) held at its rest length,
// stiffness 1; set 0 the segments with j even, set 1 those with j odd, so a
// point meets at most one partner per set. Twin:
// src/sim/reference/constraints/distance.rs.

// Per set: the partner's offset in invocations (0: none), whether own is the
// pair's first point, the rest length.
int distance_offset[2] = int[2](0, 0);
bool distance_first[2] = bool[2](false, false);
float distance_rest[2] = float[2](0.0, 0.0);

void distance_load(uint i, uint points, uint index) {
    bool has_next = i + 1u < points;
    float len_next = rest_length[index];
    float len_prev = i > 0u ? rest_length[index - 1u] : 0.0;
    if ((i & 1u) == 0u) {
        if (has_next) { distance_offset[0] = 1; distance_first[0] = true; distance_rest[0] = len_next; }
        if (i > 0u) { distance_offset[1] = -1; distance_rest[1] = len_prev; }
    } else {
        distance_offset[0] = -1; distance_rest[0] = len_prev;
        if (has_next) { distance_offset[1] = 1; distance_first[1] = true; distance_rest[1] = len_next; }
    }
}

bool distance_on(uint it) {
    return true;
}

vec4 distance_apply(uint set, vec4 own, uint lid, uint src) {
    // Set by a choice between constant indices (see bending_load).
    return set == 0u ? constraint_project_end(own, lid, distance_offset[0], distance_first[0], distance_rest[0], 1.0, src)
                     : constraint_project_end(own, lid, distance_offset[1], distance_first[1], distance_rest[1], 1.0, src);
}
