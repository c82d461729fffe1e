#include "server/coordinator_main.h"

int main(int argc, char** argv) { return vrl::server::coordinatorMain(argc, argv); }
