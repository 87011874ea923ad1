"""pyjulia4d beside POV-Ray and Mandelbulber2: speed, and speed at equal error."""
