#include "ffsr/ffsr.hpp"
int main(){}
