// Front-to-back compositing of premultiplied colour (Noguera et al. 2012,
// eq. 1), shared by the techniques that composite in the shader; the
// slicers do the same with GL blending (SliceAccumulator).

// Adds sample c (straight colour, opacity already corrected for the sample
// distance) behind what `acc` holds.
void compositeFrontToBack(inout vec4 acc, vec4 c) {
  acc.rgb += (1.0 - acc.a) * c.a * c.rgb;
  acc.a += (1.0 - acc.a) * c.a;
}

// `acc` over the (premultiplied) background: the pixel.
vec4 overBackground(vec4 acc, vec4 background) {
  return vec4(acc.rgb + (1.0 - acc.a) * background.rgb, acc.a + (1.0 - acc.a) * background.a);
}
