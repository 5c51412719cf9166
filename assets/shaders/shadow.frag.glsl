// Depth-only pass: only the depth buffer is written.

void main() {}
