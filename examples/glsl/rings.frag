// Concentric rings that drift with time: a Shadertoy shader (mainImage), ours, public domain.
// python -m reactor glsl examples/glsl/rings.frag --shadertoy --size 320x180 --out rings.png
void mainImage(out vec4 fragColor, in vec2 fragCoord) {
    vec2 p = (2.0 * fragCoord - iResolution.xy) / iResolution.y;
    float r = length(p);
    float rings = 0.5 + 0.5 * cos(24.0 * r - 3.0 * iTime);
    vec3 col = mix(vec3(0.08, 0.1, 0.2), vec3(1.0, 0.75, 0.3), rings * exp(-1.5 * r));
    if (r < 0.1) {
        col = vec3(1.0);
    }
    fragColor = vec4(pow(col, vec3(1.0 / 2.2)), 1.0);
}
