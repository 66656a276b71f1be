// Depth only: the fixed-function depth write is all the shadow pass needs.
void main() {}
