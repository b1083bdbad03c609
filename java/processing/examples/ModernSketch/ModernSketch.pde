// Draw with the mouse; the window simplifier (error-bounded, cut at corners) sends JSON v1
// strokes to a sleeve. Grey: what was sent. Blue: what the sleeve says it played (from its
// events). The sleeve's events are listed on the right; a rejected stroke says why.
// Press S (or space) to Stop: the sleeve stops and drops the rest of the drawing.
import feelmysign.processing.*;
import feelmysign.client.SleeveEvent;

String BROKER = "mqtt://127.0.0.1:1883";
String USER = "sender";
String PASSWORD = "";   // from the broker's credentials.json
String SLEEVE = "sleeve1";

FeelMySign sleeve;
String[] log = new String[12];
int logged = 0;

void setup() {
  size(1280, 720);
  sleeve = new FeelMySign(this)
    .broker(BROKER)
    .login(USER, PASSWORD)
    .sleeve(SLEEVE)
    .window()
    .start();
}

void draw() {
  background(250);
  strokeWeight(10);
  stroke(200);
  sleeve.drawSent();
  strokeWeight(4);
  stroke(30, 90, 220);
  sleeve.drawPlayed();
  strokeWeight(2);
  stroke(0);
  sleeve.drawLine();
  fill(40);
  textSize(14);
  text(sleeve.status() + "   unsent: " + sleeve.unsent(), 12, height - 12);
  for (int i = 0; i < logged; i++) {
    text(log[i], width - 330, 24 + 18 * i);
  }
}

// Called by the library inside draw(), on the sketch's thread.
void sleeveEvent(SleeveEvent event) {
  String line = event.type() + (event.seq() == null ? "" : " #" + event.seq());
  if (event.reason() != null) {
    line = line + ": " + event.reason();
  }
  if (logged == log.length) {
    arrayCopy(log, 1, log, 0, log.length - 1);
    logged--;
  }
  log[logged++] = line;
}

void keyPressed() {
  if (key == 's' || key == 'S' || key == ' ') {
    sleeve.stop();
  }
}
