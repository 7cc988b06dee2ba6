// three.js's AgX tone mapping and sRGB encoding (its ShaderChunk, included unchanged) applied to a
// texture, as three.js's output pass does: this entry point is ours, public domain.
#include <tonemapping_pars_fragment>
#include <colorspace_pars_fragment>

uniform sampler2D tDiffuse;
varying vec2 vUv;

void main() {
	vec4 texel = texture2D( tDiffuse, vUv );
	gl_FragColor = sRGBTransferOETF( vec4( AgXToneMapping( texel.rgb ), texel.a ) );
}
