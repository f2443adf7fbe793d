#version 330 core
// Depth only: the depth buffer stores the normalized distance to the nearest caster.
void main()
{
}
