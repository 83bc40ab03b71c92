// Source of block_2hex_gmsh.msh, written by Gmsh 4.8.4 (Debian 12) with
//   gmsh -3 -format msh41 block_2hex_gmsh.geo -o block_2hex_gmsh.msh
// and committed as it came out; the tests do not run Gmsh.
// Two hexahedra in a 2 x 1 x 1 box: physical volume "block", physical surface "base" (z = 0).
SetFactory("Built-in");
Point(1) = {0, 0, 0}; Point(2) = {2, 0, 0}; Point(3) = {2, 1, 0}; Point(4) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 3; Transfinite Curve{2, 4} = 2;
Transfinite Surface{1}; Recombine Surface{1};
out[] = Extrude {0, 0, 1} { Surface{1}; Layers{1}; Recombine; };
Physical Volume("block") = {out[1]};
Physical Surface("base") = {1};
