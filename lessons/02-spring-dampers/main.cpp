// Lesson 02 program: placeholder until the lesson is written.
#include <cstdio>
int main() {
  std::puts("lesson 02");
  return 0;
}
