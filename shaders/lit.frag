#version 330 core
// Two-sided Blinn-Phong with a directional light and a PCF shadow map. The back face of the cloth gets the
// flipped normal, so both sides read correctly; the ground draws an anti-aliased grid from world x, z.
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_light;

uniform vec4 u_color;             // base colour (alpha used for the disabled ground)
uniform int u_use_texture;
uniform sampler2D u_texture;
uniform vec2 u_uv_scale;
uniform int u_grid;               // 1: draw grid lines every 0.25 m, stronger every 1 m
uniform int u_use_shadow;
uniform sampler2DShadow u_shadow_map;
uniform vec3 u_light_direction;   // unit, toward the light
uniform vec3 u_camera;
uniform float u_shininess;
uniform float u_specular;

out vec4 frag_color;

float shadow_factor(vec3 n) {
    if (u_use_shadow == 0) return 1.0;
    vec3 p = v_light.xyz / v_light.w * 0.5 + 0.5;
    if (p.z > 1.0 || p.x < 0.0 || p.x > 1.0 || p.y < 0.0 || p.y > 1.0) return 1.0;
    // Slope-scaled bias against acne on surfaces at grazing angles to the light.
    float bias = max(0.0025 * (1.0 - dot(n, u_light_direction)), 0.0006);
    vec2 texel = 1.0 / vec2(textureSize(u_shadow_map, 0));
    float lit = 0.0;
    for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y) lit += texture(u_shadow_map, vec3(p.xy + vec2(x, y) * texel, p.z - bias));
    return lit / 9.0;
}

float grid_line(vec2 coord) {
    vec2 g = abs(fract(coord - 0.5) - 0.5) / fwidth(coord);
    return 1.0 - min(min(g.x, g.y), 1.0);
}

void main() {
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;
    vec4 base = u_color;
    if (u_use_texture == 1) base *= texture(u_texture, v_uv * u_uv_scale);
    if (u_grid == 1) {
        // Lines fade with distance before they get thinner than a pixel and alias into moire.
        float fade = exp(-length(u_camera - v_world) / 12.0);
        float minor = grid_line(v_world.xz * 4.0) * fade * fade;
        float major = grid_line(v_world.xz) * fade;
        base.rgb = mix(base.rgb, vec3(0.20, 0.22, 0.25), 0.35 * minor);
        base.rgb = mix(base.rgb, vec3(0.12, 0.13, 0.15), 0.7 * major);
    }
    vec3 v = normalize(u_camera - v_world);
    vec3 h = normalize(u_light_direction + v);
    float diffuse = max(dot(n, u_light_direction), 0.0);
    float specular = diffuse > 0.0 ? pow(max(dot(n, h), 0.0), u_shininess) * u_specular : 0.0;
    float shadow = shadow_factor(n);
    float hemi = 0.5 + 0.5 * n.y;  // sky above, ground bounce below
    vec3 ambient = base.rgb * mix(vec3(0.18, 0.17, 0.16), vec3(0.32, 0.34, 0.38), hemi);
    vec3 color = ambient + shadow * (base.rgb * diffuse * vec3(1.0, 0.97, 0.92) + vec3(specular));
    frag_color = vec4(pow(color, vec3(1.0 / 1.1)), base.a);
}
