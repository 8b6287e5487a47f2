// A stand-in for a VTK module of another build (test_input_command_line.cpp):
// it carries an interface mark that matches no granary.
extern "C" __attribute__((visibility("default"))) const char* granary_vtk_module_interface() {
  return "granary 0.0.0, another build";
}
