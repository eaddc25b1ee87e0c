#version 330 core
// Depth is written by the fixed function; nothing to shade.
void main() {}
