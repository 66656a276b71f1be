// irview: placeholder until the viewer issue lands; links the core library.
#include <cstdio>

int main() {
  std::fprintf(stderr, "irview: not built yet\n");
  return 2;
}
