// The same firmware without the state machine: the baseline size.sh subtracts.
volatile unsigned short control_word_in;
volatile unsigned short status_word_out;

int main() {
  for (;;) status_word_out = control_word_in;
}
