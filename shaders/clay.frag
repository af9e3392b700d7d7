#version 330 core
// A matte clay look: a warm key light from the upper left of the camera, a cool fill from
// below, a soft rim, and a little wrap so the terminator stays gentle.
in vec3 viewNormal;
in vec3 viewPosition;
uniform vec3 baseColor;
out vec4 color;
void main() {
    vec3 n = normalize(viewNormal);
    if (!gl_FrontFacing) n = -n;
    vec3 v = normalize(-viewPosition);
    vec3 key = normalize(vec3(-0.5, 0.7, 0.6));
    vec3 fill = normalize(vec3(0.6, -0.4, 0.5));
    float wrapKey = clamp((dot(n, key) + 0.25) / 1.25, 0.0, 1.0);
    float wrapFill = clamp((dot(n, fill) + 0.5) / 1.5, 0.0, 1.0);
    float rim = pow(1.0 - clamp(dot(n, v), 0.0, 1.0), 3.0);
    float spec = pow(clamp(dot(n, normalize(key + v)), 0.0, 1.0), 24.0) * 0.12;
    vec3 c = baseColor * (0.18 + 0.85 * wrapKey * vec3(1.0, 0.97, 0.92) +
                          0.25 * wrapFill * vec3(0.8, 0.88, 1.0)) +
             vec3(0.18) * rim + vec3(spec);
    color = vec4(pow(c, vec3(1.0 / 1.1)), 1.0);
}
