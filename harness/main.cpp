// geomint command line (placeholder while the harness is written).
int main() { return 0; }
