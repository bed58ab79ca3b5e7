// Marschner et al. 2003 hair scattering, factored as S = Σ_p M_p(θi, θo) · N_p(φ, θd)
// for p = R, TT, TRT, in an artist-friendly compact form:
//   M_p: normalised Gaussians in θh = (θi + θo)/2 around the shifted cuticle
//        angles α_R = α, α_TT = −α/2, α_TRT = −3α/2, widths β, β/2, 2β;
//   N_R:   ¼·cos(φ/2)·F(η′, cos(φ/2)), F with Bravais' index η′ for θd;
//   N_TT:  (1 − F0)²·g(γ_TT; π − |φ|), forward scattering around φ = π;
//   N_TRT: (1 − F0)²·F0·g(γ_TRT; |φ| − φ_glint), the glints.
// The CPU mirror is crate::render::marschner. Twin struct: gpu_types::MarschnerPush.
#ifndef VKHAIR_MARSCHNER_GLSL
#define VKHAIR_MARSCHNER_GLSL

struct MarschnerPush {
    float eta;            // index of refraction of the fiber
    float alpha;          // longitudinal shift of R (radians, usually negative)
    float beta;           // longitudinal width of R (radians)
    float gamma_tt;       // azimuthal width of TT (radians)
    float gamma_trt;      // azimuthal width of the TRT glints (radians)
    float glint;          // azimuth of the TRT glints (radians)
    uint size;            // table side, texels
    uint pad0;
};

const float MARSCHNER_PI = 3.14159265358979;

float marschner_gauss(float width, float x) {
    return exp(-0.5 * x * x / (width * width)) / (width * sqrt(2.0 * MARSCHNER_PI));
}

// Fresnel reflectance of unpolarised light at incidence cosine `cos_i`, index `eta`.
float marschner_fresnel(float eta, float cos_i) {
    float sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if (sin_t2 >= 1.0) {
        return 1.0;
    }
    float cos_t = sqrt(1.0 - sin_t2);
    float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

// (M_R, M_TT, M_TRT, cos θd) at sin θi, sin θo.
vec4 marschner_m(MarschnerPush p, float sin_i, float sin_o) {
    float theta_i = asin(clamp(sin_i, -1.0, 1.0));
    float theta_o = asin(clamp(sin_o, -1.0, 1.0));
    float theta_h = 0.5 * (theta_i + theta_o);
    float theta_d = 0.5 * (theta_o - theta_i);
    return vec4(
        marschner_gauss(p.beta, theta_h - p.alpha),
        marschner_gauss(0.5 * p.beta, theta_h + 0.5 * p.alpha),
        marschner_gauss(2.0 * p.beta, theta_h + 1.5 * p.alpha),
        cos(theta_d));
}

// (N_R, N_TT, N_TRT, 0) at cos φ, cos θd.
vec4 marschner_n(MarschnerPush p, float cos_phi, float cos_theta_d) {
    float phi = acos(clamp(cos_phi, -1.0, 1.0));
    float cd = max(cos_theta_d, 1e-3);
    float sd2 = 1.0 - cd * cd;
    float eta_p = sqrt(max(p.eta * p.eta - sd2, 1e-6)) / cd;
    float half_cos = cos(0.5 * phi);
    float f0 = marschner_fresnel(eta_p, 1.0);
    float n_r = 0.25 * half_cos * marschner_fresnel(eta_p, half_cos);
    float n_tt = (1.0 - f0) * (1.0 - f0) * marschner_gauss(p.gamma_tt, MARSCHNER_PI - phi);
    float n_trt = (1.0 - f0) * (1.0 - f0) * f0 * marschner_gauss(p.gamma_trt, phi - p.glint);
    return vec4(n_r, n_tt, n_trt, 0.0);
}

#endif
