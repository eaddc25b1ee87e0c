#version 330 core
in vec4 v_color;
uniform int u_round_points;  // 1: discard outside a disc, so particles draw as dots
out vec4 frag_color;
void main() {
    if (u_round_points == 1 && length(gl_PointCoord - vec2(0.5)) > 0.5) discard;
    frag_color = v_color;
}
