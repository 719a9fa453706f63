/* cpfg view file of flower.l */
angle increment: 25
initial color: 1
color increment: 1
initial line width: 0.3 polygons
line width increment: 0.12
viewpoint: 3,6.7,8.5
view reference point: 0,3.2,-1.5
twist: 0
projection: perspective
z buffer: on
scale factor: 0.95
tropism: T 0,-1,0 A 0 E 0.08
