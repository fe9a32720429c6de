// Arrays arrive base64-encoded, little-endian, with their dtype and shape (python/mechsys/viewer).
const TYPES = {
  float64: Float64Array, float32: Float32Array, int32: Int32Array, uint32: Uint32Array, int8: Int8Array, uint8: Uint8Array,
};

export function decode(d) {
  const Type = TYPES[d.dtype];
  if (!Type) throw new Error(`unknown array type ${d.dtype}`);
  const bin = atob(d.b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Type(bytes.buffer, 0, bytes.length / Type.BYTES_PER_ELEMENT);
}
