// Upscale the reduced-resolution ray-marched image into the viewport
// (bilinear), for ViewSettings::render_scale < 1. The vertex stage is
// fullscreen.wgsl's, prepended.

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var src_sampler: sampler;

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4f {
    return textureSample(src, src_sampler, in.uv);
}
