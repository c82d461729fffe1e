#include "worker/worker_main.h"

int main(int argc, char** argv) { return vrl::worker::workerMain(argc, argv); }
