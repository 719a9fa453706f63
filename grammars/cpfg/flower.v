/* cpfg view file of flower.l */
angle increment: 25
initial color: 1
color increment: 1
initial line width: 0.3 polygons
line width increment: 0.12
viewpoint: 0.3,0.35,1
view reference point: 0,0,0
twist: 0
projection: perspective
z buffer: on
scale factor: 0.95
tropism: T 0,-1,0 A 0 E 0.08
