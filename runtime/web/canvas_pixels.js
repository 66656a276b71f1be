// RGBA bytes of the page's WebGL 2 canvas, top row first (as a PNG), for comparisons. The context must keep
// its drawing buffer (preserveDrawingBuffer).
export function canvasPixels() {
  const canvas = document.querySelector('canvas');
  const gl = canvas.getContext('webgl2');
  const w = canvas.width, h = canvas.height;
  const px = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const flipped = new Uint8Array(px.length);
  for (let y = 0; y < h; ++y) flipped.set(px.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
  return flipped;
}
