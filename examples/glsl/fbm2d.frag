#version 450
// Source: yiwenl/glsl-fbm, 2d.glsl (commit b74844523a7c0d5e4e51965579bc93b3b547e5c3), MIT licence
// (package.json "license": "MIT"). The module's functions below are the original's, unchanged;
// the #version line above and the entry point at the end are ours (the module has no main).

float rand(vec2 n) { 
	return fract(sin(dot(n, vec2(12.9898, 4.1414))) * 43758.5453);
}

float noise(vec2 p){
	vec2 ip = floor(p);
	vec2 u = fract(p);
	u = u*u*(3.0-2.0*u);
	
	float res = mix(
		mix(rand(ip),rand(ip+vec2(1.0,0.0)),u.x),
		mix(rand(ip+vec2(0.0,1.0)),rand(ip+vec2(1.0,1.0)),u.x),u.y);
	return res*res;
}

#define NUM_OCTAVES 5

float fbm(vec2 x) {
	float v = 0.0;
	float a = 0.5;
	vec2 shift = vec2(100);
	// Rotate to reduce axial bias
    mat2 rot = mat2(cos(0.5), sin(0.5), -sin(0.5), cos(0.50));
	for (int i = 0; i < NUM_OCTAVES; ++i) {
		v += a * noise(x);
		x = rot * x * 2.0 + shift;
		a *= 0.5;
	}
	return v;
}

// --- the entry point (ours): examples/shaders/noise.py's main_image
layout(location = 0) in float frag_x;
layout(location = 1) in float frag_y;
layout(location = 0) out float gray;
uniform float height;

void main() {
    gray = fbm(vec2(frag_x, frag_y) / height * 6.0);
}
