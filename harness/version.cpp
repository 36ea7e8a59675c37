// Build provenance strings.
namespace geomint {
const char* version() { return GEOMINT_VERSION; }
}  // namespace geomint
