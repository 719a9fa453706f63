executable: honda81 -e hex_collide.e hex_collide.spec
communication type: files
turtle position:P:%.4f %.4f %.4f
