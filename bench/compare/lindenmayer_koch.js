// Derives ABOP Fig. 1.6 (quadratic Koch island) with lindenmayer.js and
// writes the word to stdout, as `sylva derive` does. Usage: node lindenmayer_koch.js N
const LSystem = require('lindenmayer');
const n = parseInt(process.argv[2] || '8', 10);
const koch = new LSystem({ axiom: 'F-F-F-F', productions: { F: 'F-F+F+FF-F-F+F' } });
koch.iterate(n);
const word = koch.getString();
process.stdout.write(word + '\n');
