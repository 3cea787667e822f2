// @gltf-transform/extensions's declarations import types from the untyped 'draco3dgltf' (its Draco
// codec options); a strict project that does not use Draco declares them (not part of @zhc/runtime).
declare module 'draco3dgltf' {
  export type Attribute = unknown;
  export type Decoder = unknown;
  export type DecoderModule = unknown;
  export type EncoderModule = unknown;
  export type Mesh = unknown;
}
