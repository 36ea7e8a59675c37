// my_geomint: geomint's whole command line (list, run, order, sweep, gate) with the user's
// methods and problem registered next to the built-in ones.
#include <harness/run_main.hpp>

#include "user_extensions.hpp"

int main(int argc, char** argv) {
  user::register_all();
  return geomint::run_main(argc, argv);
}
