#version 330 core
// Lit geometry (cloth, sphere, cube, cylinder, ground): world-space position and normal, UVs, light-space position.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;

uniform mat4 u_model;
uniform mat4 u_view_projection;
uniform mat4 u_light_view_projection;

out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_light;

void main() {
    vec4 world = u_model * vec4(a_position, 1.0);
    v_world = world.xyz;
    // Models are only translated and scaled (uniformly or per axis): the inverse-transpose keeps normals right.
    v_normal = mat3(transpose(inverse(u_model))) * a_normal;
    v_uv = a_uv;
    v_light = u_light_view_projection * world;
    gl_Position = u_view_projection * world;
}
