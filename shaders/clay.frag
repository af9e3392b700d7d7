#version 330 core
// SPDX-License-Identifier: Apache-2.0
// The surface's looks. Clay (look 0): a matte clay lit in the view, a warm key light from
// the upper left of the camera, a cool fill from below, a soft rim, and a little wrap so
// the terminator stays gentle. The others are matcaps: a colour for each direction the
// surface can face the camera, looked up by sphere mapping (the view-space normal's x and
// y as coordinates on a lit sphere), computed here rather than read from images.
in vec3 viewNormal;
in vec3 viewPosition;
uniform vec3 baseColor;
uniform int look; // 0 clay, 1 glossy, 2 red wax, 3 normals
out vec4 color;

// The normal of the matcap's sphere at sphere-map coordinates uv in [0, 1]^2.
vec3 sphereNormal(vec2 uv) {
    vec2 p = uv * 2.0 - 1.0;
    return vec3(p, sqrt(max(0.0, 1.0 - dot(p, p))));
}

// A glazed ceramic: a grey-blue body under a soft sky and a darker floor, a sharp key
// highlight and a bright Fresnel edge.
vec3 glossy(vec3 n) {
    vec3 key = normalize(vec3(-0.45, 0.6, 0.66));
    float diffuse = clamp(dot(n, key), 0.0, 1.0);
    vec3 environment = mix(vec3(0.10, 0.11, 0.13), vec3(0.55, 0.62, 0.72), 0.5 + 0.5 * n.y);
    float highlight = pow(clamp(dot(n, normalize(key + vec3(0.0, 0.0, 1.0))), 0.0, 1.0), 90.0);
    float fresnel = pow(1.0 - n.z, 4.0);
    return vec3(0.16, 0.19, 0.24) + 0.45 * diffuse * vec3(0.55, 0.6, 0.68) +
           0.35 * environment * fresnel + vec3(1.2) * highlight;
}

// A red wax: light wraps far past the terminator and the rim glows warm, as light that
// enters the wax comes back out around the edge; a dull, broad sheen.
vec3 redWax(vec3 n) {
    vec3 key = normalize(vec3(-0.4, 0.55, 0.73));
    float wrap = clamp((dot(n, key) + 0.6) / 1.6, 0.0, 1.0);
    float rim = pow(1.0 - n.z, 2.0);
    float sheen = pow(clamp(dot(n, normalize(key + vec3(0.0, 0.0, 1.0))), 0.0, 1.0), 12.0);
    return vec3(0.30, 0.02, 0.02) + wrap * vec3(0.62, 0.06, 0.05) +
           rim * vec3(0.35, 0.08, 0.03) + 0.18 * sheen * vec3(1.0, 0.75, 0.7);
}

vec3 clay(vec3 n) {
    vec3 v = normalize(-viewPosition);
    vec3 key = normalize(vec3(-0.5, 0.7, 0.6));
    vec3 fill = normalize(vec3(0.6, -0.4, 0.5));
    float wrapKey = clamp((dot(n, key) + 0.25) / 1.25, 0.0, 1.0);
    float wrapFill = clamp((dot(n, fill) + 0.5) / 1.5, 0.0, 1.0);
    float rim = pow(1.0 - clamp(dot(n, v), 0.0, 1.0), 3.0);
    float spec = pow(clamp(dot(n, normalize(key + v)), 0.0, 1.0), 24.0) * 0.12;
    return baseColor * (0.18 + 0.85 * wrapKey * vec3(1.0, 0.97, 0.92) +
                        0.25 * wrapFill * vec3(0.8, 0.88, 1.0)) +
           vec3(0.18) * rim + vec3(spec);
}

void main() {
    vec3 n = normalize(viewNormal);
    if (!gl_FrontFacing) n = -n;
    vec3 c;
    if (look == 0) {
        c = clay(n);
    } else {
        vec3 s = sphereNormal(clamp(n.xy * 0.5 + 0.5, 0.0, 1.0));
        if (look == 1)
            c = glossy(s);
        else if (look == 2)
            c = redWax(s);
        else
            c = s * 0.5 + 0.5; // the normal as a colour: x red, y green, z blue
    }
    color = vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 1.1)), 1.0);
}
