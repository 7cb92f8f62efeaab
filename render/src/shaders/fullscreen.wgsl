// The full-screen triangle both passes draw (prepended to raymarch.wgsl and
// blit.wgsl): vertex i of 3 lands at clip (-1, -1), (3, -1), (-1, 3), which
// covers the viewport. `ndc` is the clip position, `uv` the texture
// coordinate of a full-viewport image (row 0 at the top).

struct VsOut {
    @builtin(position) pos: vec4f,
    @location(0) ndc: vec2f,
    @location(1) uv: vec2f,
};

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> VsOut {
    let x = f32((i << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(i & 2u) * 2.0 - 1.0;
    var out: VsOut;
    out.pos = vec4f(x, y, 0.0, 1.0);
    out.ndc = vec2f(x, y);
    out.uv = vec2f(x * 0.5 + 0.5, 0.5 - y * 0.5);
    return out;
}

