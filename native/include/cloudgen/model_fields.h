// cloudgen/model_fields.h — the one list of Model's fields (an X-macro list).
//
// model.h expands the rows into the members of struct Model; field_key.cpp
// into the field key's hash, in this order. A field added here is therefore
// hashed too: a sequence bake can no longer copy a stale frame because the
// key missed what the kernel reads. The order and types are part of the key:
// reordering rows, or changing a type, changes every key (bump
// kFieldKeyVersion in field_key.h when doing so on purpose).
//
// Rows:
//   CG_MODEL_FIELD(type, name, key_rule)          one value: float, int or vec3
//   CG_MODEL_ARRAY(type, name, count, key_rule)   a fixed-size array of floats
// key_rule says when the value reaches the field (see field_key.cpp):
//   Always         always hashed
//   ExponentShape  only when shape_mode is 0 (the profile uses the exponent)
//   CurveShape     only when shape_mode is 1 (the profile uses the curve)
//
// Include this file only after defining both macros.
//
// clang-format off
CG_MODEL_FIELD(vec3, box, Always)                                // box dimensions, scene units (> 0)
CG_MODEL_FIELD(float, cloud_scale, Always)
CG_MODEL_FIELD(int, shape_mode, Always)
CG_MODEL_FIELD(float, shape_exponent, ExponentShape)
CG_MODEL_ARRAY(float, curve, CG_CURVE_POINTS, CurveShape)
CG_MODEL_FIELD(float, distortion, Always)
CG_MODEL_FIELD(float, density, Always)                           // physical multiplier (slider × 20)
CG_MODEL_FIELD(float, worley_frequency, Always)                  // lattice cells per scene unit
CG_MODEL_FIELD(float, perlin_frequency, Always)
CG_MODEL_FIELD(vec3, worley_offset, Always)                      // wrapped, in lattice units
CG_MODEL_FIELD(vec3, perlin_offset, Always)
CG_MODEL_FIELD(float, w4, Always)                                // 4th noise coordinate (time × evolution, wrapped)
CG_MODEL_FIELD(float, worley_influence, Always)
CG_MODEL_FIELD(float, worley_clump, Always)
CG_MODEL_FIELD(float, wave, Always)
CG_MODEL_FIELD(float, noise_influence, Always)
CG_MODEL_FIELD(float, noise_detail, Always)
CG_MODEL_FIELD(float, noise_whisp, Always)
CG_MODEL_FIELD(int, seed, Always)
CG_MODEL_FIELD(float, edge_width, Always)                        // cg_edge_width(Edge Sharpness), in (0, 1]
CG_MODEL_FIELD(float, base_height, Always)                       // flat floor and ceiling, in h
CG_MODEL_FIELD(float, top_height, Always)
CG_MODEL_FIELD(float, lean, Always)
CG_MODEL_FIELD(float, sheet, Always)
CG_MODEL_FIELD(float, anvil, Always)                             // narrowing below the anvil: 1 + 4 anvil
CG_MODEL_FIELD(float, anvil_height, Always)                      // where the anvil starts, in h
CG_MODEL_FIELD(float, stretch, Always)                           // noise warp
CG_MODEL_FIELD(float, shear, Always)
CG_MODEL_FIELD(float, warp, Always)                              // domain warp, warp cells
CG_MODEL_FIELD(float, warp_frequency, Always)                    // warp cells per scene unit
CG_MODEL_FIELD(vec3, warp_offset, Always)                        // wrapped, in warp lattice units
CG_MODEL_FIELD(float, turret_influence, Always)
CG_MODEL_FIELD(float, turret_frequency, Always)                  // turret cells per scene unit (x, y)
CG_MODEL_FIELD(vec3, turret_offset, Always)                      // wrapped, in turret lattice units
CG_MODEL_FIELD(float, fibres, Always)                            // Fibres weight (cg_fibre_noise)
CG_MODEL_FIELD(float, anvil_fibres, Always)                      // Anvil Fibres weight (cg_anvil_fibre_cut)
// clang-format on
