// POV-Ray's documentation example (POV-Ray 3.6 documentation, "A simple example of a julia fractal
// object"), with a camera and a light added so that it can be seen.
// doc_example_alpha.png: POV-Ray 3.7.0.10 (Debian) rendered this file with
//   povray +Idoc_example.pov +Odoc_example_alpha.png +W64 +H48 -D -A +UA
// and only its alpha channel (hit or not) was kept.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera {
  location <1.5, 1.0, -3.5>
  look_at <0, 0, 0>
  right x*image_width/image_height
  angle 45
}
light_source { <1.5, 1.0, -3.5> color rgb 1 shadowless }
julia_fractal {
  <-0.083,0.0,-0.83,-0.025>
  quaternion
  sqr
  max_iteration 8
  precision 15
  pigment { color rgb <0.95, 0.72, 0.42> }
}
