"""Plain NumPy reference implementations, written from the documented definitions (the
theory page's equations), that tests compare the compiled code against."""
