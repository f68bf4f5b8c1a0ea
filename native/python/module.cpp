// placeholder: being written
#define Py_LIMITED_API 0x030B0000
#include <Python.h>
static struct PyModuleDef def = {PyModuleDef_HEAD_INIT, "cloudgen_native", nullptr, -1, nullptr, nullptr, nullptr, nullptr, nullptr};
PyMODINIT_FUNC PyInit_cloudgen_native(void) { return PyModule_Create(&def); }
