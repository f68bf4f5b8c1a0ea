// cloudgen/field_key.h — 16 hex digits that identify a density field.
//
// Equal keys mean equal fields (the key hashes everything the kernel reads,
// see field_key.cpp); a sequence bake copies a frame whose key it has baked
// already, and `bake --update` keeps a file whose stored key is unchanged.
#pragma once

#include <string>

#include "cloudgen/model.h"

namespace cg {

// Bumped whenever the kernel's output changes for the same Model.
inline constexpr int kFieldKeyVersion = 1;

std::string field_key(const Model& m);
std::string field_key(const Params& p);

}  // namespace cg
