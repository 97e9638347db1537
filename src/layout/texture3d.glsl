// sampleVolume for Texture3DLayout: one hardware-trilinear fetch.
uniform highp sampler3D u_layoutVolume;

float sampleVolume(vec3 p) { return texture(u_layoutVolume, p).r; }
