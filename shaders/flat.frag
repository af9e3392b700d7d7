#version 330 core
// SPDX-License-Identifier: Apache-2.0
uniform vec4 tint;
out vec4 color;
void main() {
    color = tint;
}
