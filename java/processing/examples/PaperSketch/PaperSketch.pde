// The sketch of "Can You Feel My Sign?" rebuilt on the feelmysign library: draw with the
// mouse on a 1920x1080 canvas; the paper's angle simplifier (appendix B.1's defaults) cuts
// the path into straight strokes, each sent as the paper's text to deviceOne/line; the
// strokes sent so far are drawn in red. A new press clears them (clickClear).
//
// Start a broker and a sleeve first (in the feelmysign repository):
//   feelmysign broker          prints the broker's address and the sender's password
//   feelmysign sleeve --backend sim
import feelmysign.processing.*;

String BROKER = "mqtt://127.0.0.1:1883";
String USER = "sender";
String PASSWORD = "";   // from the broker's credentials.json
String SLEEVE = "sleeve1";  // whose events (played, rejected, ...) the sketch hears

FeelMySign sleeve;

void setup() {
  size(1920, 1080);
  frameRate(60);         // B.1's fps
  sleeve = new FeelMySign(this)
    .broker(BROKER)
    .login(USER, PASSWORD)
    .sleeve(SLEEVE)
    .angle()             // B.1's defaults: frameMax 0 (no limit), checkFrame 5, maxAngleDifDeg 20, ...
    .set("screenX", 1920)
    .set("screenY", 1080)
    .legacy()            // "startX,startY,endX,endY,duration" on deviceOne/line
    .start();
}

void draw() {
  background(255);
  strokeWeight(6);
  stroke(220, 40, 40);
  sleeve.drawSent();     // the previously sent vectors
  strokeWeight(2);
  stroke(0);
  sleeve.drawLine();     // the line being drawn
  fill(90);
  textSize(18);
  text(sleeve.status(), 16, height - 16);
}
