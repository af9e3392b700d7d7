#version 330 core
// SPDX-License-Identifier: Apache-2.0
// Lines and shells drawn in one colour: the ground grid, the wireframe, the tool.
layout(location = 0) in vec3 position;
uniform mat4 viewProjection;
uniform mat4 model;
void main() {
    gl_Position = viewProjection * model * vec4(position, 1.0);
}
