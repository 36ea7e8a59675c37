// The geomint program: the command line of harness/run_main.cpp with the built-in registries.
#include "harness/run_main.hpp"

int main(int argc, char** argv) { return geomint::run_main(argc, argv); }
