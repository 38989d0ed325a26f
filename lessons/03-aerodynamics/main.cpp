// Lesson 03 program: placeholder until the lesson is written.
#include <cstdio>
int main() {
  std::puts("lesson 03");
  return 0;
}
