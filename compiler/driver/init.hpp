// Starting the interpreter: every layer's primitives installed, the library
// loaded.
#pragma once

namespace sicm {

// Set up the global environment: every primitive, then the Scheme library.
// Call once, after GC_INIT(), on the thread that will evaluate.
void init_interpreter();

} // namespace sicm
