// cloudgen/field_key.h — 16 hex digits that identify a density field.
//
// Equal keys mean equal fields (the key hashes everything the kernel reads,
// see field_key.cpp). Different keys mean different parameters as the kernel
// sees them; the fields then differ too except in degenerate cases the key
// folds (density 0: one key for every empty field). A sequence bake copies a
// frame whose key it has baked already, and `bake --update` keeps a file
// whose stored key is unchanged.
#pragma once

#include <string>

#include "cloudgen/grid.h"
#include "cloudgen/model.h"

namespace cg {

// Bumped whenever the kernel's output changes for the same Model. The test
// Golden.KernelMatchesTheDensityFingerprint (tests/native/test_golden.cpp)
// fails on such a change and says how to regenerate its fingerprint file.
inline constexpr int kFieldKeyVersion = 5;  // 5: the sheet's cap (2026-12-03); 4: Anvil Fibres (2026-12-02)

std::string field_key(const Model& m);
std::string field_key(const Params& p);

// The key of a bake's voxels: the field key, then a hash of what else decides
// them — the grid, LOD, drop tolerance, storage precision (`half`), the
// camera region and the ring. Stored in the VDB; `bake --update` compares it.
std::string bake_key(const Model& m, const BakeOptions& options, bool half);

}  // namespace cg
