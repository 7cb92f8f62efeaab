// Volcad viewport: one fullscreen triangle (fullscreen.wgsl, prepended);
// per pixel a ray is marched through the baked volume (distance R16Float, colour and fractions
// Rgba8Unorm, all trilinear), then overlays (ground grid, bounding box,
// axis triad) are composited analytically.
//
// World units are mm, z is up. Texture coordinate of p: (p - grid_min) / grid_size.

struct Uniforms {
    eye: vec4f,        // xyz eye, w 1 = orthographic
    right: vec4f,      // xyz, w half-extent factor x
    up: vec4f,         // xyz, w half-extent factor y
    forward: vec4f,    // xyz
    grid_min: vec4f,   // xyz, w voxel (mm)
    grid_size: vec4f,  // xyz, w surface bias (mm)
    bbox_min: vec4f,   // xyz, w 1 = volume loaded
    bbox_max: vec4f,   // xyz, w volume optical depth per mm
    background: vec4f,
    cut: vec4f,        // kept where dot(xyz, p) + w <= 0
    iso: vec4f,        // x level, y channel (-1 none), z channels, w colour from fractions
    opacity: vec4f,    // per channel
    palette: array<vec4f, 4>,
    flags: vec4u,      // x mode (0 solid, 1 volume, 2 iso), y overlays (1 bbox, 2 grid, 4 axes, 8 cut), z hidden material
    viewport: vec4f,   // x, y size (px), z ground grid spacing (mm)
};

@group(0) @binding(0) var<uniform> u: Uniforms;
@group(0) @binding(1) var t_dist: texture_3d<f32>;
@group(0) @binding(2) var t_color: texture_3d<f32>;
@group(0) @binding(3) var t_frac: texture_3d<f32>;
@group(0) @binding(4) var s_lin: sampler;

// Pipeline constants: one pipeline per drawing path, so each compiles to
// only its own code.
// VOLUME: translucent accumulation. REGION: draw a sub-region of the part
// (iso surface or hidden materials; one extra lookup per step).
override VOLUME: bool = false;
override REGION: bool = false;

const MAX_STEPS: i32 = 384;
const MAX_VOLUME_STEPS: i32 = 320;
const VOLUME_SAMPLES: f32 = 224.0;
const BIG: f32 = 1.0e30;

// ---- volume lookups -------------------------------------------------------

fn uvw(p: vec3f) -> vec3f {
    return (p - u.grid_min.xyz) / u.grid_size.xyz;
}

// Baked distance (mm); beyond the grid, plus the distance to the grid box.
fn dist(p: vec3f) -> f32 {
    let lo = u.grid_min.xyz;
    let hi = lo + u.grid_size.xyz;
    let q = clamp(p, lo, hi);
    return textureSampleLevel(t_dist, s_lin, uvw(q), 0.0).r + length(p - q);
}

fn cut_dist(p: vec3f) -> f32 {
    if ((u.flags.y & 8u) == 0u) {
        return -BIG;
    }
    return dot(u.cut.xyz, p) + u.cut.w;
}

// The drawn solid: the part dilated by the thin-feature bias, minus the cut.
fn scene(p: vec3f) -> f32 {
    return max(dist(p) - u.grid_size.w, cut_dist(p));
}

fn fracs(p: vec3f) -> vec4f {
    return textureSampleLevel(t_frac, s_lin, uvw(p), 0.0);
}

fn visible() -> vec4f {
    return step(vec4f(1.0e-3), u.opacity);
}

// > 0 where the point belongs to what is drawn, for the pipelines that
// draw a sub-region of the part (iso surface, hidden materials). One
// fraction lookup.
fn region(p: vec3f) -> f32 {
    let f = fracs(p);
    if (u.flags.x == 2u) {
        let c = i32(u.iso.y);
        if (c < 0) {
            return -1.0;
        }
        return f[c] - u.iso.x + 1.0e-3;
    }
    let total = f.x + f.y + f.z + f.w;
    let other = max(0.0, 1.0 - total);
    return (dot(f, visible()) + other) / max(total + other, 1.0e-3) - 0.5;
}

fn albedo(p: vec3f) -> vec3f {
    let baked = textureSampleLevel(t_color, s_lin, uvw(p), 0.0).rgb;
    if (u.iso.w < 0.5) {
        return baked;
    }
    var w = fracs(p);
    if (u.flags.x == 0u) {
        w = w * visible();
    }
    let total = w.x + w.y + w.z + w.w;
    if (total < 1.0e-3) {
        return baked;
    }
    let c = w.x * u.palette[0].rgb + w.y * u.palette[1].rgb + w.z * u.palette[2].rgb + w.w * u.palette[3].rgb;
    return c / total;
}

fn grad_dist(p: vec3f, h: f32) -> vec3f {
    let k = vec2f(1.0, -1.0);
    return k.xyy * dist(p + k.xyy * h) + k.yyx * dist(p + k.yyx * h)
         + k.yxy * dist(p + k.yxy * h) + k.xxx * dist(p + k.xxx * h);
}

fn grad_region(p: vec3f, h: f32) -> vec3f {
    let k = vec2f(1.0, -1.0);
    return k.xyy * region(p + k.xyy * h) + k.yyx * region(p + k.yyx * h)
         + k.yxy * region(p + k.yxy * h) + k.xxx * region(p + k.xxx * h);
}

fn safe_normalize(v: vec3f, fallback: vec3f) -> vec3f {
    let l = length(v);
    if (l < 1.0e-12) {
        return fallback;
    }
    return v / l;
}

// ---- shading ---------------------------------------------------------------

fn key_light() -> vec3f {
    return normalize(-u.forward.xyz * 1.0 - u.right.xyz * 0.45 + u.up.xyz * 0.7);
}

// Ambient occlusion from the distance field along the normal.
fn occlusion(p: vec3f, n: vec3f) -> f32 {
    let s = max(u.grid_min.w * 1.5, length(u.bbox_max.xyz - u.bbox_min.xyz) * 0.012);
    var occ = 0.0;
    var w = 1.0;
    for (var i = 1; i <= 4; i++) {
        let h = s * f32(i);
        occ += w * clamp((h - scene(p + n * h)) / h, 0.0, 1.0);
        w *= 0.6;
    }
    return clamp(1.0 - 0.45 * occ, 0.35, 1.0);
}

fn shade(base: vec3f, p: vec3f, n_in: vec3f, rd: vec3f) -> vec3f {
    var n = n_in;
    if (dot(n, rd) > 0.0) {
        n = -n;
    }
    let l = key_light();
    let v = -rd;
    let diff = max(dot(n, l), 0.0);
    let fill = max(dot(n, v), 0.0);
    let sky = 0.5 + 0.5 * n.z;
    let ao = occlusion(p, n);
    let h = normalize(l + v);
    let spec = pow(max(dot(n, h), 0.0), 48.0) * 0.18;
    let light = ao * (0.24 + 0.10 * sky) + 0.50 * diff + 0.24 * fill;
    return base * light + vec3f(spec);
}

// ---- rays -------------------------------------------------------------------

struct Ray {
    o: vec3f,
    d: vec3f,
};

fn camera_ray(ndc: vec2f) -> Ray {
    var r: Ray;
    if (u.eye.w > 0.5) {
        r.o = u.eye.xyz + u.right.xyz * (ndc.x * u.right.w) + u.up.xyz * (ndc.y * u.up.w);
        r.d = u.forward.xyz;
    } else {
        r.o = u.eye.xyz;
        r.d = normalize(u.forward.xyz + u.right.xyz * (ndc.x * u.right.w) + u.up.xyz * (ndc.y * u.up.w));
    }
    return r;
}

// Size of one pixel (mm) at ray parameter t.
fn pixel_mm(t: f32) -> f32 {
    if (u.eye.w > 0.5) {
        return 2.0 * u.up.w / u.viewport.y;
    }
    return 2.0 * u.up.w * max(t, 0.0) / u.viewport.y;
}

// Entry and exit of the ray through a box (t1 < t0: miss).
fn box_hit(r: Ray, lo: vec3f, hi: vec3f) -> vec2f {
    let inv = 1.0 / r.d;
    let a = (lo - r.o) * inv;
    let b = (hi - r.o) * inv;
    let tmin = min(a, b);
    let tmax = max(a, b);
    return vec2f(max(max(tmin.x, tmin.y), max(tmin.z, 0.0)), min(min(tmax.x, tmax.y), tmax.z));
}

// The march domain: voxel centres of the grid (outside them the texture
// clamps).
fn march_box(r: Ray) -> vec2f {
    let half_voxel = 0.5 * u.grid_min.w;
    return box_hit(r, u.grid_min.xyz + half_voxel, u.grid_min.xyz + u.grid_size.xyz - half_voxel);
}

// Where a surface march stopped: t (BIG: missed), and whether the hit is a
// region boundary inside the part (normal from the region's gradient).
struct Hit {
    t: f32,
    t_prev: f32,
    inner: bool,
};

// Solid and Iso modes. Loop bodies stay minimal (one distance lookup, plus
// one fraction lookup in REGION pipelines): software rasterisers execute
// every branch of a loop body, taken or not, so all shading happens once,
// after the loop.
fn march_surface(r: Ray) -> Hit {
    var hit: Hit;
    hit.t = BIG;
    hit.inner = false;
    let span = march_box(r);
    if (span.y < span.x) {
        return hit;
    }
    let voxel = u.grid_min.w;
    var t = span.x;
    var inside_prev = false;
    var t_prev = t;
    for (var i = 0; i < MAX_STEPS; i++) {
        if (t > span.y) {
            break;
        }
        let p = r.o + r.d * t;
        let d = scene(p);
        let eps = clamp(0.5 * pixel_mm(t), 0.01 * voxel, 0.25 * voxel);
        if (d < eps) {
            if (!REGION || region(p) > 0.0) {
                hit.t = t;
                hit.t_prev = t_prev;
                hit.inner = REGION && inside_prev;
                break;
            }
            // Inside the part but outside the region: fractions vary
            // smoothly, so step a voxel and bisect the crossing afterwards.
            inside_prev = true;
            t_prev = t;
            t += voxel;
        } else {
            inside_prev = false;
            t_prev = t;
            t += max(d * 0.9, 0.05 * voxel);
        }
    }
    return hit;
}

fn shade_hit(r: Ray, h: Hit) -> vec3f {
    let voxel = u.grid_min.w;
    var t = h.t;
    var n: vec3f;
    if (REGION && h.inner) {
        // Region boundary inside the part: bisect it, normal from its gradient.
        var a = h.t_prev;
        var b = h.t;
        for (var k = 0; k < 7; k++) {
            let m = 0.5 * (a + b);
            if (region(r.o + r.d * m) > 0.0) { b = m; } else { a = m; }
        }
        t = b;
        n = safe_normalize(-grad_region(r.o + r.d * t, 0.75 * voxel), -r.d);
    } else {
        let q = r.o + r.d * t;
        let eps = clamp(0.5 * pixel_mm(t), 0.01 * voxel, 0.25 * voxel);
        if (cut_dist(q) > dist(q) - u.grid_size.w - 0.5 * eps) {
            n = u.cut.xyz;
        } else {
            n = safe_normalize(grad_dist(q, 0.5 * voxel), -r.d);
        }
    }
    let q = r.o + r.d * t;
    return shade(albedo(q), q, n, r.d);
}

// Volume mode: front-to-back accumulation inside the part; empty space is
// skipped with the distance field. Returns (colour, transmittance).
fn march_volume(r: Ray) -> vec4f {
    let span = march_box(r);
    if (span.y < span.x) {
        return vec4f(0.0, 0.0, 0.0, 1.0);
    }
    let voxel = u.grid_min.w;
    // At most VOLUME_SAMPLES samples through the grid box (plus the empty
    // space skips): the frame cost stays bounded at 256³.
    let dt = max(voxel, (span.y - span.x) / VOLUME_SAMPLES);
    var t = span.x;
    var acc = vec3f(0.0);
    var trans = 1.0;
    var t_skin = BIG;
    var skin_col = vec3f(0.0);
    var skin_sigma = 0.0;
    for (var i = 0; i < MAX_VOLUME_STEPS; i++) {
        if (t > span.y || trans < 0.02) {
            break;
        }
        let p = r.o + r.d * t;
        let d = max(dist(p), cut_dist(p));
        if (d > voxel) {
            t += max(0.9 * (d - 0.5 * voxel), dt);
        } else {
            let inside = 1.0 - smoothstep(-0.5 * voxel, 0.5 * voxel, d);
            var col: vec3f;
            var sigma: f32;
            if (u.iso.w > 0.5) {
                let f = fracs(p) * u.opacity;
                let w = f * vec4f(u.palette[0].a, u.palette[1].a, u.palette[2].a, u.palette[3].a);
                sigma = w.x + w.y + w.z + w.w;
                let c = w.x * u.palette[0].rgb + w.y * u.palette[1].rgb + w.z * u.palette[2].rgb + w.w * u.palette[3].rgb;
                col = c / max(sigma, 1.0e-4);
            } else {
                let c = textureSampleLevel(t_color, s_lin, uvw(p), 0.0);
                col = c.rgb;
                sigma = max(c.a, 0.08) * (u.opacity.x + u.opacity.y + u.opacity.z + u.opacity.w) * 0.25;
            }
            if (t_skin == BIG && inside > 0.5 && sigma > 0.0) {
                t_skin = t;
                skin_col = col;
                skin_sigma = sigma;
            }
            sigma *= inside * u.bbox_max.w;
            let a = 1.0 - exp(-sigma * dt);
            acc += trans * a * col;
            trans *= 1.0 - a;
            t += dt;
        }
    }
    if (t_skin < BIG) {
        // A faint lit skin where the ray entered, for shape cues; it sits in
        // front of everything accumulated (which started at the entry).
        let p = r.o + r.d * t_skin;
        var n = safe_normalize(grad_dist(p, 0.5 * voxel), -r.d);
        if (cut_dist(p) > dist(p) - 0.5 * voxel) {
            n = u.cut.xyz;
        }
        let skin = 0.22 * min(1.0, skin_sigma);
        acc = skin * shade(skin_col, p, n, r.d) + (1.0 - skin) * acc;
        trans *= 1.0 - skin;
    }
    return vec4f(acc, trans);
}

// ---- overlays ----------------------------------------------------------------

// Closest approach of ray and segment ab: (distance, ray t).
fn ray_segment(r: Ray, a: vec3f, b: vec3f) -> vec2f {
    let ba = b - a;
    let w = r.o - a;
    let dba = dot(r.d, ba);
    let bb = dot(ba, ba);
    let den = bb - dba * dba;
    var s = 0.0;
    if (den > 1.0e-9 * bb) {
        s = clamp((dot(ba, w) - dba * dot(r.d, w)) / den, 0.0, 1.0);
    }
    let q = a + ba * s;
    let t = max(dot(q - r.o, r.d), 0.0);
    return vec2f(length(r.o + r.d * t - q), t);
}

fn line_alpha(dt: vec2f, t_limit: f32, width_px: f32) -> f32 {
    if (dt.y > t_limit) {
        return 0.0;
    }
    let px = max(pixel_mm(dt.y), 1.0e-6);
    return clamp(width_px * 0.5 + 0.5 - dt.x / px, 0.0, 1.0);
}

fn bbox_overlay(r: Ray, t_hit: f32) -> f32 {
    let lo = u.bbox_min.xyz;
    let hi = u.bbox_max.xyz;
    var a = 0.0;
    for (var e = 0; e < 12; e++) {
        let axis = e / 4;
        let k = e % 4;
        var p0 = lo;
        var p1 = lo;
        // The two other axes take lo/hi by the bits of k.
        let o1 = (axis + 1) % 3;
        let o2 = (axis + 2) % 3;
        if ((k & 1) != 0) { p0[o1] = hi[o1]; }
        if ((k & 2) != 0) { p0[o2] = hi[o2]; }
        p1 = p0;
        p1[axis] = hi[axis];
        a = max(a, line_alpha(ray_segment(r, p0, p1), t_hit, 1.25));
    }
    return a;
}

fn grid_overlay(r: Ray, t_hit: f32) -> f32 {
    let z = u.bbox_min.z;
    if (abs(r.d.z) < 1.0e-5) {
        return 0.0;
    }
    let t = (z - r.o.z) / r.d.z;
    if (t <= 0.0 || t > t_hit) {
        return 0.0;
    }
    let p = r.o + r.d * t;
    let c = 0.5 * (u.bbox_min.xy + u.bbox_max.xy);
    let extent = max(u.bbox_max.x - u.bbox_min.x, u.bbox_max.y - u.bbox_min.y);
    let radius = max(extent * 1.5, 4.0 * u.viewport.z);
    let fade = 1.0 - smoothstep(0.5 * radius, radius, length(p.xy - c));
    let s = u.viewport.z;
    let px = pixel_mm(t) / max(abs(r.d.z), 0.15);
    let g = abs(fract(p.xy / s + 0.5) - 0.5) * s;
    let g10 = abs(fract(p.xy / (10.0 * s) + 0.5) - 0.5) * 10.0 * s;
    let minor = clamp(1.0 - min(g.x, g.y) / px, 0.0, 1.0) * 0.35 * clamp(s / px / 4.0 - 0.25, 0.0, 1.0);
    let major = clamp(1.2 - min(g10.x, g10.y) / px, 0.0, 1.0) * 0.6;
    return max(minor, major) * fade;
}

// Axis triad in the lower-left corner, in pixels. Returns premultiplied rgba.
fn axes_overlay(ndc: vec2f) -> vec4f {
    let px = (ndc * 0.5 + 0.5) * u.viewport.xy;
    let size = clamp(min(u.viewport.x, u.viewport.y) * 0.07, 18.0, 48.0);
    let c = vec2f(size + 10.0, size + 10.0);
    var out = vec4f(0.0);
    // Draw the axis pointing most away first.
    var depth = vec3f(u.forward.x, u.forward.y, u.forward.z);
    for (var n = 0; n < 3; n++) {
        // Pick the remaining axis with the largest depth (farthest).
        var best = -1;
        var best_d = -BIG;
        for (var a = 0; a < 3; a++) {
            if (depth[a] > best_d) { best_d = depth[a]; best = a; }
        }
        depth[best] = -BIG * 2.0;
        var e = vec3f(0.0);
        e[best] = 1.0;
        let dir = vec2f(dot(e, u.right.xyz), dot(e, u.up.xyz));
        let tip = c + dir * size;
        let pa = px - c;
        let ba = tip - c;
        let h = clamp(dot(pa, ba) / max(dot(ba, ba), 1.0e-6), 0.0, 1.0);
        let dd = length(pa - ba * h);
        let alpha = clamp(1.75 - dd, 0.0, 1.0);
        var col = vec3f(0.9, 0.25, 0.25);
        if (best == 1) { col = vec3f(0.3, 0.85, 0.3); }
        if (best == 2) { col = vec3f(0.3, 0.5, 1.0); }
        out = vec4f(mix(out.rgb, col, alpha), max(out.a, alpha));
    }
    return out;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4f {
    let r = camera_ray(in.ndc);
    var color = u.background.rgb;
    var t_hit = BIG;
    let has_volume = u.bbox_min.w > 0.5;
    if (has_volume) {
        let contrast = select(vec3f(0.0), vec3f(1.0), dot(u.background.rgb, vec3f(0.333)) < 0.5);
        if (VOLUME) {
            // The grid lies behind the translucent part: composite over it.
            var behind = u.background.rgb;
            if ((u.flags.y & 2u) != 0u) {
                behind = mix(behind, contrast, grid_overlay(r, BIG) * 0.5);
            }
            let v = march_volume(r);
            color = v.rgb + v.a * behind;
        } else {
            let h = march_surface(r);
            if (h.t < BIG) {
                t_hit = h.t;
                color = shade_hit(r, h);
            }
        }
        if (!VOLUME && (u.flags.y & 2u) != 0u) {
            color = mix(color, contrast, grid_overlay(r, t_hit) * 0.5);
        }
        if ((u.flags.y & 1u) != 0u) {
            color = mix(color, mix(contrast, vec3f(1.0, 0.8, 0.3), 0.5), bbox_overlay(r, t_hit) * 0.8);
        }
    }
    if ((u.flags.y & 4u) != 0u) {
        let a = axes_overlay(in.ndc);
        color = mix(color, a.rgb, a.a);
    }
    return vec4f(clamp(color, vec3f(0.0), vec3f(1.0)), 1.0);
}
