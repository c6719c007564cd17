// figurine renderer shaders: lit limb capsules, ground grid, soft ground shadows, 2-D overlay.
// All colours are linear; the render target is sRGB so the hardware encodes on store.

struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // height, grid spacing, fade radius, line width (in grid cells)
    ground: vec4<f32>,
    // ground centre x, z; viewport width, height in pixels
    centre_viewport: vec4<f32>,
    background: vec4<f32>,
    // key light direction (towards the light), w unused
    light: vec4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;

// ---------------------------------------------------------------- capsules

struct CapsuleIn {
    // unit direction in the bone's local frame (y along the bone), w: 0 = start cap, 1 = end cap
    @location(0) dir_end: vec4<f32>,
    // start xyz, radius
    @location(1) a: vec4<f32>,
    // end xyz
    @location(2) b: vec4<f32>,
    @location(3) colour: vec4<f32>,
};

struct CapsuleOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) world: vec3<f32>,
    @location(2) colour: vec3<f32>,
};

@vertex
fn vs_capsule(v: CapsuleIn) -> CapsuleOut {
    let axis = v.b.xyz - v.a.xyz;
    let len = length(axis);
    var y = vec3<f32>(0.0, 1.0, 0.0);
    if (len > 1e-9) {
        y = axis / len;
    }
    var helper = vec3<f32>(1.0, 0.0, 0.0);
    if (abs(y.x) > 0.9) {
        helper = vec3<f32>(0.0, 0.0, 1.0);
    }
    let x = normalize(cross(helper, y));
    let z = cross(x, y);
    let n = x * v.dir_end.x + y * v.dir_end.y + z * v.dir_end.z;
    let centre = mix(v.a.xyz, v.b.xyz, v.dir_end.w);
    let world = centre + n * v.a.w;
    var out: CapsuleOut;
    out.clip = g.view_proj * vec4<f32>(world, 1.0);
    out.normal = n;
    out.world = world;
    out.colour = v.colour.rgb;
    return out;
}

@fragment
fn fs_capsule(in: CapsuleOut) -> @location(0) vec4<f32> {
    let n = normalize(in.normal);
    let view = normalize(g.eye.xyz - in.world);
    let key = normalize(g.light.xyz);
    let diffuse = max(dot(n, key), 0.0);
    // Sky/ground hemisphere ambient: lit from above, darker from below.
    let ambient = mix(vec3<f32>(0.10, 0.09, 0.09), vec3<f32>(0.34, 0.36, 0.40), 0.5 + 0.5 * n.y);
    let h = normalize(key + view);
    let spec = pow(max(dot(n, h), 0.0), 40.0) * 0.18;
    let rim = pow(1.0 - max(dot(n, view), 0.0), 3.0) * 0.22;
    // Slightly darker towards the ground: a cheap contact occlusion.
    let height = (in.world.y - g.ground.x) / max(g.ground.y * 3.5, 1e-6);
    let occl = mix(0.7, 1.0, clamp(height * 4.0, 0.0, 1.0));
    let c = in.colour * (ambient + diffuse * 0.9) * occl + vec3<f32>(spec + rim);
    return vec4<f32>(c, 1.0);
}

// ---------------------------------------------------------------- ground grid

struct GroundOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
};

fn quad_corner(i: u32) -> vec2<f32> {
    // Two triangles covering [-1, 1]^2.
    var c = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    return c[i];
}

@vertex
fn vs_ground(@builtin(vertex_index) i: u32) -> GroundOut {
    let c = quad_corner(i);
    let r = g.ground.z;
    let world = vec3<f32>(g.centre_viewport.x + c.x * r, g.ground.x, g.centre_viewport.y + c.y * r);
    var out: GroundOut;
    out.clip = g.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    return out;
}

@fragment
fn fs_ground(in: GroundOut) -> @location(0) vec4<f32> {
    let p = in.world.xz / g.ground.y;
    let w = max(fwidth(p), vec2<f32>(1e-6));
    // Distance to the nearest line, in pixels; lines are ~1 px plus a width in cells.
    let d = abs(fract(p - 0.5) - 0.5);
    let line_px = (d - g.ground.w) / w;
    var line = 1.0 - clamp(min(line_px.x, line_px.y), 0.0, 1.0);
    // Fade lines out where cells get smaller than a few pixels (avoids moire).
    line *= clamp(1.5 - 4.0 * max(w.x, w.y), 0.0, 1.0);
    // The world axes through the origin are drawn a little stronger.
    let axis_px = abs(in.world.xz) / (w * g.ground.y);
    let axis = 1.0 - clamp(min(axis_px.x, axis_px.y) - 0.5, 0.0, 1.0);
    let base = vec3<f32>(0.72, 0.71, 0.68);
    let ink = vec3<f32>(0.42, 0.42, 0.42);
    var c = mix(base, ink, max(line * 0.55, axis * 0.75));
    let r = distance(in.world.xz, g.centre_viewport.xy) / g.ground.z;
    let fog = smoothstep(0.35, 1.0, r);
    c = mix(c, g.background.rgb, fog);
    return vec4<f32>(c, 1.0);
}

// ---------------------------------------------------------------- ground shadows

struct ShadowIn {
    // ground (x, z) of both ends
    @location(0) ends: vec4<f32>,
    // core radius, blur width, darkness, unused
    @location(1) params: vec4<f32>,
};

struct ShadowOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) xz: vec2<f32>,
    @location(1) ends: vec4<f32>,
    @location(2) params: vec4<f32>,
};

@vertex
fn vs_shadow(@builtin(vertex_index) i: u32, s: ShadowIn) -> ShadowOut {
    let a = s.ends.xy;
    let b = s.ends.zw;
    var u = b - a;
    let len = length(u);
    if (len > 1e-9) {
        u = u / len;
    } else {
        u = vec2<f32>(1.0, 0.0);
    }
    let v = vec2<f32>(-u.y, u.x);
    let e = s.params.x + s.params.y;
    let c = quad_corner(i);
    let mid = (a + b) * 0.5;
    let xz = mid + u * c.x * (len * 0.5 + e) + v * c.y * e;
    var out: ShadowOut;
    out.clip = g.view_proj * vec4<f32>(xz.x, g.ground.x, xz.y, 1.0);
    out.xz = xz;
    out.ends = s.ends;
    out.params = s.params;
    return out;
}

@fragment
fn fs_shadow(in: ShadowOut) -> @location(0) vec4<f32> {
    let a = in.ends.xy;
    let b = in.ends.zw;
    let ab = b - a;
    let t = clamp(dot(in.xz - a, ab) / max(dot(ab, ab), 1e-12), 0.0, 1.0);
    let d = distance(in.xz, a + ab * t);
    let core = in.params.x;
    let blur = max(in.params.y, 1e-6);
    let k = 1.0 - smoothstep(core - 0.5 * blur, core + blur, d);
    let dark = clamp(in.params.z * k, 0.0, 0.95);
    // Multiplicative blending: the result is ground colour times this.
    return vec4<f32>(vec3<f32>(1.0 - dark), 1.0);
}

// ---------------------------------------------------------------- overlay rectangles

struct RectIn {
    // left, top, right, bottom in pixels
    @location(0) xyxy: vec4<f32>,
    @location(1) colour: vec4<f32>,
};

struct RectOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) colour: vec4<f32>,
};

@vertex
fn vs_rect(@builtin(vertex_index) i: u32, r: RectIn) -> RectOut {
    let c = quad_corner(i) * 0.5 + 0.5;
    let px = mix(r.xyxy.xy, r.xyxy.zw, c);
    let size = g.centre_viewport.zw;
    var out: RectOut;
    out.clip = vec4<f32>(px.x / size.x * 2.0 - 1.0, 1.0 - px.y / size.y * 2.0, 0.0, 1.0);
    out.colour = r.colour;
    return out;
}

@fragment
fn fs_rect(in: RectOut) -> @location(0) vec4<f32> {
    return in.colour;
}
