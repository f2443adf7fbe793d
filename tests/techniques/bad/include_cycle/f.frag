#include "f.frag"
