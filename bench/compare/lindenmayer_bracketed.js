// Derives ABOP Fig. 1.24a (bracketed plant, F --> F[+F]F[-F]F) with
// lindenmayer.js and writes the word to stdout, as `sylva derive` does.
// Usage: node lindenmayer_bracketed.js N
const LSystem = require('lindenmayer');
const n = parseInt(process.argv[2] || '7', 10);
const plant = new LSystem({ axiom: 'F', productions: { F: 'F[+F]F[-F]F' } });
plant.iterate(n);
process.stdout.write(plant.getString() + '\n');
