// Installers for the groups of primitives, called once at startup.
#pragma once

namespace sicm {

void install_text_primitives();   // characters, strings, symbols
void install_vector_primitives(); // vectors

} // namespace sicm
