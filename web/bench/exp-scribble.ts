import { benchScribble } from "./scribble";
const s = await benchScribble();
console.log(JSON.stringify(s));
