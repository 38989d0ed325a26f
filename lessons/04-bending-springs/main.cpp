// Lesson 04 program: placeholder until the lesson is written.
#include <cstdio>
int main() {
  std::puts("lesson 04");
  return 0;
}
