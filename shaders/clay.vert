#version 330 core
// SPDX-License-Identifier: Apache-2.0
// Clay surface: positions and SDF-gradient normals in world space, shaded in view space.
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 viewProjection;
uniform mat4 view;
out vec3 viewNormal;
out vec3 viewPosition;
void main() {
    viewNormal = mat3(view) * normal;
    viewPosition = (view * vec4(position, 1.0)).xyz;
    gl_Position = viewProjection * vec4(position, 1.0);
}
