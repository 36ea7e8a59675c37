// The key of a structure interface a problem may offer (docs/DESIGN.md §2, "Structures"):
// Problem::as<Structure>() finds an interface by the address of its key, so the Problem base
// names no concrete structure and a new one needs no change to it.
#pragma once

namespace geomint {

// One per structure interface, as its `static constexpr StructureKey kStructureKey`: an inline
// variable, so its address is one object program-wide and identifies the interface without RTTI
// (no typeid comparison that could differ between shared libraries). The texts are for messages:
// "method 'boris' integrates <what> only (<offered_by>); problem 'x' is none".
struct StructureKey {
  const char* name;        // "free_rigid_body"
  const char* what;        // "free rigid bodies"
  const char* offered_by;  // the problems that offer it and what they give
};

}  // namespace geomint
